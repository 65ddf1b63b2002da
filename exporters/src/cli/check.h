// `chaintube check PROJECT --clearance METRES`: hose-to-scene clearance violations.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace chaintube::cli {

/// Exit code of `check` when the check ran and found violations (0: none, 1: the work failed,
/// 2: bad command line, as for every subcommand).
constexpr int kExitViolations = 3;

struct CheckCommand
{
    std::string project;
    double clearance = -1.0; ///< metres; required
    bool includeAttached = false;
    std::vector<std::string> roots; ///< NAME=DIR
};

/// Registers `check` on `app`; its options are written into `command`.
void addCheckCommand(CLI::App& app, CheckCommand& command);

int runCheck(const CheckCommand& command, std::ostream& out, std::ostream& err);

} // namespace chaintube::cli
