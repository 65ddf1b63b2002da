// `chaintube check PROJECT --clearance METRES`: hose-to-scene clearance violations;
// `chaintube check PROJECT --sweep`: the same and the hoses' limits over the project's motions;
// `chaintube check PROJECT --fit-length`: the range of valid lengths of hoses between fixed ends.
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
/// Exit code of `check --sweep` when the project has no motions (nothing was swept), and of
/// `check --fit-length` when no hose is between fixed ends (nothing to fit).
constexpr int kExitNoMotions = 4;
/// Exit code of `check --fit-length` when some hose has no valid length.
constexpr int kExitNoValidLength = 5;

struct CheckCommand
{
    std::string project;
    double clearance = -1.0; ///< metres (−1: not given: the project's threshold, else 0.005)
    bool includeAttached = false;
    std::vector<std::string> roots; ///< NAME=DIR
    bool sweep = false;             ///< drive the project's motions (exporting::sweepProject)
    int steps = 0;                  ///< --steps: sweep steps each way (0: not given, 20)
    bool json = false;              ///< --json: the sweep report as JSON on stdout
    bool quiet = false;             ///< -q: no progress on stderr
    bool fitLength = false;         ///< --fit-length (exporting::fitProjectLengths)
    std::vector<std::string> hoses; ///< --hose: the hoses to fit (none: every fittable one)
    double tolerance = 0.001;       ///< --tolerance: metres, each end of the range
};

/// Registers `check` on `app`; its options are written into `command`.
void addCheckCommand(CLI::App& app, CheckCommand& command);

int runCheck(const CheckCommand& command, std::ostream& out, std::ostream& err);

} // namespace chaintube::cli
