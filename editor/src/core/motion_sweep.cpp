#include "chaintube/editor/motion_sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace chaintube::editor {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Radians or metres per slider tick: 0.1° or 0.1 mm.
double tickSize(const formats::PartMotion& motion)
{
    return motion.kind == formats::PartMotion::Kind::Hinge ? 0.1 * kPi / 180.0 : 1e-4;
}

} // namespace

MotionTicks motionTicks(const formats::PartMotion& motion)
{
    const double tick = tickSize(motion);
    // The small margins keep a range end that is a whole number of ticks from getting one more.
    return {static_cast<int>(std::floor(motion.minimum / tick + 1e-9)),
            static_cast<int>(std::ceil(motion.maximum / tick - 1e-9))};
}

double motionValueOfTick(const formats::PartMotion& motion, int tick)
{
    return std::clamp(tick * tickSize(motion), motion.minimum, motion.maximum);
}

int motionTickOfValue(const formats::PartMotion& motion, double value)
{
    const MotionTicks ticks = motionTicks(motion);
    return std::clamp(static_cast<int>(std::lround(value / tickSize(motion))), ticks.minimum,
                      ticks.maximum);
}

std::string formatMotionValue(const formats::PartMotion& motion, double value)
{
    const bool hinge = motion.kind == formats::PartMotion::Kind::Hinge;
    double shown = hinge ? value * 180.0 / kPi : value * 1000.0;
    if (std::abs(shown) < 0.05) shown = 0.0; // never "-0.0"
    char text[64];
    std::snprintf(text, sizeof text, hinge ? "%.1f°" : "%.1f mm", shown);
    return text;
}

std::string describeMotionValues(const std::vector<formats::PartMotion>& motions,
                                 const std::vector<double>& values)
{
    std::string text;
    for (size_t i = 0; i < motions.size() && i < values.size(); ++i) {
        if (i > 0) text += ", ";
        text += motions[i].id + " at " + formatMotionValue(motions[i], values[i]);
    }
    return text;
}

double driveParameterOf(const formats::PartMotion& motion, double value)
{
    return (value - motion.minimum) / (motion.maximum - motion.minimum);
}

namespace {

std::string hoseName(const formats::Project& project, const std::string& hoseId)
{
    for (const formats::HoseDefinition& definition : project.hoses)
        if (definition.id == hoseId) return definition.name.empty() ? hoseId : definition.name;
    return hoseId;
}

std::string millimetres(double metres)
{
    char text[64];
    std::snprintf(text, sizeof text, "%.1f mm", std::abs(metres) < 0.5e-4 ? 0.0 : metres * 1000.0);
    return text;
}

} // namespace

MotionPlotSeries plotSeries(const exporting::SweepReport& report, const formats::Project& project,
                            size_t hose)
{
    const exporting::HoseSweep& swept = report.hoses.at(hose);
    MotionPlotSeries series;
    series.hoseId = swept.hoseId;
    series.hoseName = hoseName(project, swept.hoseId);
    series.minBendRadius = swept.minBendRadius;
    series.clearanceThreshold = report.clearanceThreshold;
    for (size_t step = 0; step < report.steps.size(); ++step) {
        const exporting::SweepStep& at = report.steps[step];
        if (!at.t) continue; // off the path (the project's pose, the lead-in)
        using Phase = exporting::SweepStep::Phase;
        // The lead-in's last step is t = 0, the first point of the way out.
        MotionPlotSeries::Line& line = at.phase == Phase::Back ? series.back : series.out;
        line.t.push_back(*at.t);
        line.bendRadius.push_back(swept.bendRadiusSeries.at(step));
        line.clearance.push_back(swept.clearanceSeries.at(step));
    }
    return series;
}

std::vector<SweepFinding> sweepFindings(const exporting::SweepReport& report,
                                        const formats::Project& project)
{
    std::vector<SweepFinding> findings;
    const int stepCount = static_cast<int>(report.steps.size());
    for (const exporting::HoseSweep& swept : report.hoses) {
        if (!swept.violates()) continue;
        const std::string name = hoseName(project, swept.hoseId);
        const auto add = [&](int step, const std::string& what, int steps) {
            SweepFinding finding;
            finding.hoseId = swept.hoseId;
            finding.step = step;
            if (step >= 0 && step < stepCount) finding.values = report.steps[size_t(step)].values;
            finding.text = name + " — sweep, " +
                           describeMotionValues(report.motions, finding.values) + ": " + what +
                           ", on " + std::to_string(steps) + " of " + std::to_string(stepCount) +
                           " steps";
            findings.push_back(std::move(finding));
            return &findings.back();
        };
        if (swept.overstretched()) {
            char what[128];
            std::snprintf(what, sizeof what,
                          "overstretched, a segment %.1f %% beyond its length "
                          "(band %.1f %%)",
                          swept.worstStretch * 100.0, swept.stretchBand * 100.0);
            SweepFinding* finding = add(swept.worstStretchStep, what, swept.overstretchedSteps);
            finding->firstPoint = swept.worstStretchSegment;
            finding->lastPoint = swept.worstStretchSegment + 1;
        }
        if (swept.bendViolated()) {
            const std::string what = swept.minBendRadius > 0.0
                                         ? "bend radius " + millimetres(swept.smallestBendRadius) +
                                               " < " + millimetres(swept.minBendRadius)
                                         : "bends beyond its deflection angle (radius " +
                                               millimetres(swept.smallestBendRadius) + ")";
            SweepFinding* finding =
                add(swept.smallestBendRadiusStep, what, swept.bendViolationSteps);
            finding->firstPoint = finding->lastPoint = swept.smallestBendRadiusJoint;
        }
        if (swept.beyondReach())
            add(swept.worstAttachmentGapStep,
                "needs " + millimetres(swept.worstAttachmentGap) + " more hose to reach its part",
                swept.unmetSteps);
        for (const exporting::ObjectSweep& object : swept.objects) {
            if (object.stepsBelowThreshold == 0 && !object.collides()) continue;
            const std::string how =
                object.minDistance < 0.0
                    ? millimetres(-object.minDistance) + " into " + object.objectPath
                    : millimetres(object.minDistance) + " from " + object.objectPath;
            SweepFinding* finding = add(
                object.step, how + " (clearance " + millimetres(report.clearanceThreshold) + ")",
                std::max(object.stepsBelowThreshold, 1));
            finding->firstPoint = finding->lastPoint = object.axisPoint;
            finding->sceneId = object.sceneId;
            finding->objectPath = object.objectPath;
        }
    }
    return findings;
}

} // namespace chaintube::editor
