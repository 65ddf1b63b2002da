#include "check.h"

#include "commands.h"

#include <CLI/CLI.hpp>
#include <chaintube/export/clearance.h>
#include <iomanip>

namespace chaintube::cli {

void addCheckCommand(CLI::App& app, CheckCommand& command)
{
    CLI::App* check = app.add_subcommand(
        "check", "Check a project's hoses against its scene objects: every hose that comes closer "
                 "to an object (a scene node with meshes) than --clearance is listed with the "
                 "object's path, the distance, the nearest axis point and the world position");
    check->footer("Example:\n  chaintube check samples/engine.ctproj --clearance 0.005 --root "
                  "scenes=../shared/scenes\n"
                  "Exit codes: 0 no violation, 1 the check could not run (unreadable or invalid "
                  "project, scene import failed), 2 bad command line, 3 violations found.");
    check->add_option("project", command.project, "Project file (*.ctproj)")->required();
    check
        ->add_option("--clearance", command.clearance,
                     "Minimum distance in metres between a hose's surface and any scene object "
                     "(e.g. 0.005)")
        ->required()
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                double value = -1.0;
                try {
                    size_t used = 0;
                    value = std::stod(text, &used);
                    if (used != text.size()) value = -1.0;
                } catch (const std::exception&) {
                }
                if (value >= 0.0 && value < 1e300) return {};
                return "expected a distance >= 0 in metres (e.g. 0.005), got '" + text + "'";
            },
            "METRES"));
    check->add_flag("--include-attached", command.includeAttached,
                    "Also check each hose against the nodes it is attached to (skipped by default: "
                    "a hose end sits in its fitting by design)");
    check->add_option("--root", command.roots,
                      "Named root for project paths \"NAME:path\", as NAME=DIR (repeatable)");
}

int runCheck(const CheckCommand& command, std::ostream& out, std::ostream& err)
{
    formats::NamedRoots roots;
    for (const std::string& root : command.roots) {
        const size_t equals = root.find('=');
        if (equals == std::string::npos || equals == 0 || equals + 1 == root.size()) {
            err << "chaintube check: --root '" << root
                << "': expected NAME=DIR, e.g. scenes=../shared/scenes\n";
            return kExitUsage;
        }
        roots[root.substr(0, equals)] = root.substr(equals + 1);
    }
    exporting::ClearanceOptions options;
    options.threshold = command.clearance;
    options.includeAttachedNodes = command.includeAttached;
    const std::vector<exporting::ClearanceFinding> violations =
        exporting::checkProjectClearance(command.project, roots, options);
    out << std::setprecision(6);
    for (const exporting::ClearanceFinding& v : violations)
        out << "violation: hose " << v.hoseId << ", object " << v.sceneId << ":" << v.objectPath
            << ", distance " << v.distance << " m, axis point " << v.axisPoint << ", at ("
            << v.onObject.x() << ", " << v.onObject.y() << ", " << v.onObject.z() << ") m\n";
    out << command.project << ": " << violations.size() << " clearance violation(s) below "
        << command.clearance << " m\n";
    return violations.empty() ? kExitOk : kExitViolations;
}

} // namespace chaintube::cli
