// `chaintube check PROJECT --clearance METRES`: hose-to-scene clearance violations;
// `chaintube check PROJECT --sweep`: the same and the hoses' limits over the project's motions.
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
/// Exit code of `check --sweep` when the project has no motions: nothing was swept.
constexpr int kExitNoMotions = 4;

struct CheckCommand
{
    std::string project;
    double clearance = -1.0; ///< metres; required without --sweep (−1: not given)
    bool includeAttached = false;
    std::vector<std::string> roots; ///< NAME=DIR
    bool sweep = false;             ///< drive the project's motions (exporting::sweepProject)
    int steps = 20;                 ///< --steps: sweep steps each way
    bool json = false;              ///< --json: the sweep report as JSON on stdout
    bool quiet = false;             ///< -q: no progress on stderr
};

/// Registers `check` on `app`; its options are written into `command`.
void addCheckCommand(CLI::App& app, CheckCommand& command);

int runCheck(const CheckCommand& command, std::ostream& out, std::ostream& err);

} // namespace chaintube::cli
