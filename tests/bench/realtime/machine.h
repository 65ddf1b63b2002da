// chaintube-bench-realtime: what a measurement log names — commit, date, machine, command —
// and pinning the process to one CPU.
#pragma once

#include <filesystem>
#include <string>

namespace chaintube::bench::realtime {

/// `git rev-parse --short=12 HEAD` in `sourceDir`, with " (+ local changes)" when `git status
/// --porcelain` lists any; "unknown" when git or the repository is not available.
std::string gitCommit(const std::filesystem::path& sourceDir);
/// The CPU's model name as `lscpu` shows it, its family and model numbers and the number of
/// CPUs (/proc/cpuinfo), or "unknown".
std::string cpuModel();
/// Now, UTC, "2024-09-01 12:34:56 UTC".
std::string utcDate();
/// The 1-minute load average (/proc/loadavg), or "unknown".
std::string loadAverage();
/// Restricts this process to CPU `cpu` (sched_setaffinity). False, with `error`, on failure.
bool pinToCpu(int cpu, std::string& error);
/// The CPUs this process may run on, e.g. "1" or "0-1" (sched_getaffinity).
std::string allowedCpus();

} // namespace chaintube::bench::realtime
