// `chaintube demo`: builds and deforms the built-in sample hoses and reports what happened.
#pragma once

#include <ostream>

namespace chaintube::cli {

/// Runs the demo, writing a human-readable report to out. Returns a process exit code.
int runDemo(std::ostream& out);

} // namespace chaintube::cli
