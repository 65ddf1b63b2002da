#include "check.h"

#include "commands.h"

#include <CLI/CLI.hpp>
#include <chaintube/export/clearance.h>
#include <chaintube/export/fit_length.h>
#include <chaintube/export/sweep.h>
#include <chaintube/formats/project.h>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace chaintube::cli {

namespace {

CLI::Validator distanceValidator()
{
    return CLI::Validator(
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
        "METRES");
}

/// "step 12 (out, t 0.6: lever 0.48 rad, carriage 0.072 m)".
std::string describeStep(const exporting::SweepReport& report, int step)
{
    if (step < 0 || step >= static_cast<int>(report.steps.size())) return "no step";
    const exporting::SweepStep& at = report.steps[static_cast<size_t>(step)];
    std::ostringstream text;
    text << std::setprecision(4) << "step " << step << " (" << exporting::toString(at.phase);
    if (at.t) text << ", t " << *at.t;
    text << ":";
    for (size_t m = 0; m < report.motions.size(); ++m)
        text << (m ? ", " : " ") << report.motions[m].id << " " << at.values[m]
             << (report.motions[m].kind == formats::PartMotion::Kind::Hinge ? " rad" : " m");
    text << ")";
    return text.str();
}

void printSweep(const exporting::SweepReport& report, const std::string& project, std::ostream& out)
{
    out << std::setprecision(4);
    out << "sweep of " << project << ": " << report.motions.size() << " motion(s), "
        << report.stepsEachWay << " steps each way, lead-in " << report.leadInSteps << ", "
        << report.steps.size() << " steps (t 0 -> 1 -> 0)\n";
    for (const formats::PartMotion& motion : report.motions)
        out << "  " << motion.id << ": " << formats::toString(motion.kind) << " of " << motion.scene
            << ":" << motion.node << ", " << motion.minimum << " ... " << motion.maximum
            << (motion.kind == formats::PartMotion::Kind::Hinge ? " rad\n" : " m\n");
    int violating = 0;
    for (const exporting::HoseSweep& hose : report.hoses) {
        violating += hose.violates();
        out << "hose " << hose.hoseId << (hose.driven ? " (on a moving part)" : "") << ": "
            << (hose.violates() ? "VIOLATION" : "ok") << "\n";
        out << "  stretch: worst " << 100.0 * hose.worstStretch << " % (band "
            << 100.0 * hose.stretchBand << " %) at " << describeStep(report, hose.worstStretchStep)
            << ", segment " << hose.worstStretchSegment << "\n";
        if (hose.overstretched())
            out << "    beyond the band on " << hose.overstretchedSteps << " step(s), first at "
                << describeStep(report, hose.firstOverstretchedStep) << "\n";
        out << "  bend radius: ";
        if (std::isfinite(hose.smallestBendRadius))
            out << "smallest " << hose.smallestBendRadius << " m";
        else
            out << "straight at every step";
        if (hose.minBendRadius > 0.0) out << " (minimum " << hose.minBendRadius << " m)";
        if (std::isfinite(hose.smallestBendRadius))
            out << " at " << describeStep(report, hose.smallestBendRadiusStep) << ", joint "
                << hose.smallestBendRadiusJoint;
        out << "\n";
        if (hose.bendViolated())
            out << "    beyond the bend limit on " << hose.bendViolationSteps
                << " step(s), first at " << describeStep(report, hose.firstBendViolationStep)
                << "\n";
        if (hose.beyondReach())
            out << "  reach: an attachment beyond the hose's reach on " << hose.unmetSteps
                << " step(s), first at " << describeStep(report, hose.firstUnmetStep)
                << "; worst gap " << hose.worstAttachmentGap << " m at "
                << describeStep(report, hose.worstAttachmentGapStep) << "\n";
        if (hose.objects.empty())
            out << "  clearance: no object within " << report.reportDistance << " m\n";
        for (const exporting::ObjectSweep& object : hose.objects) {
            out << "  clearance: " << object.sceneId << ":" << object.objectPath << " "
                << object.minDistance << " m" << (object.collides() ? " (collision)" : "") << " at "
                << describeStep(report, object.step) << ", axis point " << object.axisPoint << "\n";
            if (object.stepsBelowThreshold > 0)
                out << "    below " << report.clearanceThreshold << " m on "
                    << object.stepsBelowThreshold << " step(s), steps "
                    << object.firstStepBelowThreshold << " ... " << object.lastStepBelowThreshold
                    << "\n";
        }
        if (hose.updates.empty()) {
            out << "  updates: all Ok\n";
        } else {
            out << "  updates not Ok: " << hose.updates.size() << "\n";
            constexpr size_t kListed = 10;
            for (size_t u = 0; u < hose.updates.size() && u < kListed; ++u) {
                const exporting::SweepUpdate& update = hose.updates[u];
                out << "    " << toString(update.status) << " at "
                    << describeStep(report, update.step);
                if (update.attachmentGap > 0.0)
                    out << ", attachment gap " << update.attachmentGap << " m";
                if (update.angleViolation > 0.0)
                    out << ", bend beyond its limit by " << update.angleViolation << " rad";
                out << "\n";
            }
            if (hose.updates.size() > kListed)
                out << "    ... and " << hose.updates.size() - kListed << " more\n";
        }
    }
    out << project << ": " << report.hoses.size() << " hose(s) swept over " << report.steps.size()
        << " steps, " << violating << " with violations (clearance threshold "
        << report.clearanceThreshold << " m)\n";
}

void printFit(const exporting::LengthFitReport& report, const std::string& project,
              std::ostream& out)
{
    out << std::setprecision(4);
    out << "length fit of " << project << ": ";
    if (report.motions.empty()) {
        out << "no motions, the project's pose only";
    } else {
        out << "over " << report.motions.size() << " motion(s) (";
        for (size_t m = 0; m < report.motions.size(); ++m)
            out << (m ? ", " : "") << report.motions[m].id;
        out << "), " << report.sweptSteps << " steps a sweep";
    }
    out << ", tolerance " << report.tolerance << " m, clearance threshold "
        << report.clearanceThreshold << " m\n";
    int invalid = 0;
    for (const exporting::LengthFit& fit : report.hoses) {
        out << "hose " << fit.hoseId << " (length " << fit.currentLength << " m): ";
        if (!fit.valid) {
            ++invalid;
            out << "NO VALID LENGTH: " << fit.reason << "\n";
        } else {
            out << fit.shortest << " ... " << fit.longest << " m"
                << (fit.longestAtSearchLimit ? " (valid up to the search limit)" : "")
                << (fit.currentValid ? ", the current length is in the range"
                                     : ", the current length is OUTSIDE the range")
                << "\n";
            out << "  shorter: " << exporting::toString(fit.shortestLimit) << " (taut bound "
                << fit.tautBound << " m)";
            if (fit.longestAtSearchLimit)
                out << "; longer: no limit up to the search limit\n";
            else
                out << "; longer: " << exporting::toString(fit.longestLimit)
                    << (fit.limitingObject.empty()
                            ? std::string()
                            : " (" + fit.limitingObject + " at " +
                                  std::to_string(fit.limitingDistance) + " m)")
                    << "\n";
        }
        out << "  " << fit.sweeps << " sweep(s)" << (fit.converged ? "" : ", budget ran out")
            << "\n";
    }
    out << project << ": " << report.hoses.size() << " hose(s) fitted, " << invalid
        << " without a valid length\n";
}

} // namespace

void addCheckCommand(CLI::App& app, CheckCommand& command)
{
    CLI::App* check = app.add_subcommand(
        "check", "Check a project's hoses against its scene objects: every hose that comes closer "
                 "to an object (a scene node with meshes) than --clearance is listed with the "
                 "object's path, the distance, the nearest axis point and the world position. "
                 "With --sweep, every moving part of the project (its \"motions\": hinges and "
                 "sliders) is driven through its range and back, the hoses follow as at run "
                 "time, and each hose's worst stretch, smallest bend radius, clearance to each "
                 "object and updates that were not Ok are reported with the motion values where "
                 "they occur");
    check->footer(
        "Examples:\n  chaintube check samples/engine.ctproj --clearance 0.005 --root "
        "scenes=../shared/scenes\n"
        "  chaintube check samples/motion-rig.ctproj --sweep --steps 40 --clearance 0.005\n"
        "  chaintube check samples/motion-rig.ctproj --sweep --json -q > sweep.json\n"
        "  chaintube check samples/motion-rig.ctproj --fit-length --hose lever-feed\n"
        "Sweep: all motions are driven by one parameter t, each at min + t (max - min); t goes "
        "0 -> 1 -> 0 in --steps steps each way, after a lead-in from the project's pose "
        "(every motion at 0) to t = 0. Without --clearance a sweep uses the project's threshold "
        "(\"checks\": {\"clearance\"}) or, when it sets none, reports collisions only "
        "(distance < 0).\n"
        "Fit length: for each hose with both ends fixed (or --hose), the shortest length that "
        "is never pulled taut between its held points, never stretched beyond its band, never "
        "beyond reach and never bent beyond its limit over the sweep, and the longest that "
        "also keeps --clearance (0: no collision), searched up to twice the shortest; each "
        "end to --tolerance. Without motions, the project's pose alone.\n"
        "Exit codes: 0 no violation, 1 the check could not run (unreadable or invalid "
        "project, scene import failed), 2 bad command line, 3 violations found (clearance; "
        "with --sweep also stretch beyond the band, a bend beyond the limit, an attachment "
        "beyond reach, a collision), 4 --sweep on a project without motions (nothing swept) or "
        "--fit-length without a hose between fixed ends, 5 --fit-length: a hose has no valid "
        "length.");
    check->add_option("project", command.project, "Project file (*.ctproj)")->required();
    check
        ->add_option("--clearance", command.clearance,
                     "Minimum distance in metres between a hose's surface and any scene object "
                     "(e.g. 0.005); default: the project's threshold (\"checks\": "
                     "{\"clearance\"}), else 0.005")
        ->check(distanceValidator());
    check->add_flag("--include-attached", command.includeAttached,
                    "Also check each hose against the nodes it is attached to (skipped by default: "
                    "a hose end sits in its fitting by design)");
    check->add_option("--root", command.roots,
                      "Named root for project paths \"NAME:path\", as NAME=DIR (repeatable)");
    CLI::Option* sweep = check->add_flag(
        "--sweep", command.sweep,
        "Drive the project's motions through their ranges and back and check the hoses at "
        "every step");
    CLI::Option* fit = check->add_flag(
        "--fit-length", command.fitLength,
        "Find the range of lengths for which each hose between fixed ends stays valid over the "
        "motions (the project's pose without motions)");
    fit->excludes(sweep);
    check
        ->add_option("--hose", command.hoses,
                     "Fit length: the hose to fit, by id (repeatable; default every hose with "
                     "both ends fixed)")
        ->needs(fit);
    check
        ->add_option("--tolerance", command.tolerance,
                     "Fit length: each end of the range to within this many metres (default "
                     "0.001)")
        ->check(CLI::PositiveNumber)
        ->needs(fit);
    check
        ->add_option("--steps", command.steps,
                     "Sweep and fit length: steps each way, 1 ... 100000 (default 20)")
        ->check(CLI::Range(1, 100000));
    check->add_flag("--json", command.json, "Sweep and fit length: the report as JSON on stdout");
    check->add_flag("-q,--quiet", command.quiet, "Sweep and fit length: no progress on stderr");
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
    if (!command.sweep && !command.fitLength) {
        const char* needsSweep = command.json    ? "--json"
                                 : command.quiet ? "--quiet"
                                 : command.steps ? "--steps"
                                                 : nullptr;
        if (needsSweep) {
            err << "chaintube check: " << needsSweep << " requires --sweep or --fit-length\n";
            return kExitUsage;
        }
    }
    const int steps = command.steps > 0 ? command.steps : 20;
    // Sweep and fit length without --clearance: the project's threshold when it sets one, else
    // 0 (collisions only).
    const auto sweepClearance = [&] {
        if (command.clearance >= 0.0) return command.clearance;
        formats::ProjectLoadOptions load;
        load.roots = roots;
        return formats::loadProject(command.project, load).checks.clearance.value_or(0.0);
    };
    if (command.fitLength) {
        exporting::LengthFitOptions options;
        options.steps = steps;
        options.clearanceThreshold = sweepClearance();
        options.includeAttachedNodes = command.includeAttached;
        options.tolerance = command.tolerance;
        int lastTenth = -1;
        if (!command.quiet)
            options.progress = [&](double fraction) {
                const int tenth = static_cast<int>(fraction * 10.0);
                if (tenth != lastTenth) err << "  fit length " << 10 * tenth << " %\n";
                lastTenth = tenth;
                return true;
            };
        const exporting::LengthFitReport report =
            exporting::fitProjectLengths(command.project, roots, command.hoses, options);
        if (report.hoses.empty()) {
            err << command.project
                << ": no hose has both ends held by attachments: nothing to fit\n";
            return kExitNoMotions;
        }
        if (command.json)
            out << exporting::lengthFitJson(report, command.project);
        else
            printFit(report, command.project, out);
        return report.allValid() ? kExitOk : kExitNoValidLength;
    }
    if (command.sweep) {
        exporting::SweepOptions options;
        options.steps = steps;
        options.clearanceThreshold = sweepClearance();
        options.includeAttachedNodes = command.includeAttached;
        int lastTenth = -1;
        if (!command.quiet)
            options.progress = [&](double fraction) {
                const int tenth = static_cast<int>(fraction * 10.0);
                if (tenth != lastTenth) err << "  sweep " << 10 * tenth << " %\n";
                lastTenth = tenth;
                return true;
            };
        const exporting::SweepReport report =
            exporting::sweepProject(command.project, roots, options);
        if (report.steps.empty()) {
            err << command.project
                << ": the project has no motions (\"motions\": hinges and sliders, project "
                   "format 1.4): nothing to sweep\n";
            return kExitNoMotions;
        }
        if (command.json)
            out << exporting::sweepReportJson(report, command.project);
        else
            printSweep(report, command.project, out);
        return report.violations() ? kExitViolations : kExitOk;
    }
    // Without --clearance: the project's own threshold ("checks"/"clearance"), else the default.
    double threshold = command.clearance;
    std::string whose = "";
    if (threshold < 0.0) {
        formats::ProjectLoadOptions load;
        load.roots = roots;
        const formats::Project project = formats::loadProject(command.project, load);
        threshold = project.checks.clearance.value_or(formats::kDefaultClearance);
        whose = project.checks.clearance ? " (the project's threshold)"
                                         : " (the default threshold: the project sets none)";
    }
    exporting::ClearanceOptions options;
    options.threshold = threshold;
    options.includeAttachedNodes = command.includeAttached;
    const std::vector<exporting::ClearanceFinding> violations =
        exporting::checkProjectClearance(command.project, roots, options);
    out << std::setprecision(6);
    for (const exporting::ClearanceFinding& v : violations)
        out << "violation: hose " << v.hoseId << ", object " << v.sceneId << ":" << v.objectPath
            << ", distance " << v.distance << " m, axis point " << v.axisPoint << ", at ("
            << v.onObject.x() << ", " << v.onObject.y() << ", " << v.onObject.z() << ") m\n";
    out << command.project << ": " << violations.size() << " clearance violation(s) below "
        << threshold << " m" << whose << "\n";
    return violations.empty() ? kExitOk : kExitViolations;
}

} // namespace chaintube::cli
