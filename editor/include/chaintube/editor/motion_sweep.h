// ChainTube editor — the Motions dock's rules without Qt: slider ticks of a project motion, how
// a motion value is written, and the findings and plot series of a motion sweep
// (exporting::sweepMotions, the same sweep as `chaintube check --sweep`).
#pragma once

#include "chaintube/export/sweep.h"
#include "chaintube/formats/project.h"

#include <string>
#include <vector>

namespace chaintube::editor {

/// A motion slider's integer range: one tick is 0.1° of a hinge or 0.1 mm of a slider, tick 0
/// is the project's pose (value 0). minimum = floor(motion.minimum / tick), maximum =
/// ceil(motion.maximum / tick), so the end ticks reach the range's ends (motionValueOfTick
/// clamps).
struct MotionTicks
{
    int minimum = 0;
    int maximum = 0;
};
MotionTicks motionTicks(const formats::PartMotion& motion);
/// The value of `tick` (radians or metres), clamped to [motion.minimum, motion.maximum].
double motionValueOfTick(const formats::PartMotion& motion, int tick);
/// The tick nearest `value` (radians or metres), within motionTicks(motion).
int motionTickOfValue(const formats::PartMotion& motion, double value);

/// A value as a person reads it: "35.0°" for a hinge (value in radians), "12.0 mm" for a
/// slider (value in metres), one decimal, never "-0.0".
std::string formatMotionValue(const formats::PartMotion& motion, double value);
/// "lever at 35.0°, carriage at 12.0 mm": every motion at its value (one per motion).
std::string describeMotionValues(const std::vector<formats::PartMotion>& motions,
                                 const std::vector<double>& values);

/// The drive parameter t ∈ [0, 1] of a sweep where `motion` is at `value`:
/// (value − minimum) / (maximum − minimum) (formats::motionValueAt inverted).
double driveParameterOf(const formats::PartMotion& motion, double value);

/// One hose's plot over a sweep: bend radius and clearance against the drive parameter t, the
/// steps going out (t 0 → 1) and coming back (1 → 0) as separate lines, and the limits.
struct MotionPlotSeries
{
    std::string hoseId;
    std::string hoseName; ///< the definition's name, or its id
    struct Line
    {
        std::vector<double> t;
        std::vector<double> bendRadius; ///< metres; infinity: straight
        std::vector<double> clearance;  ///< metres; infinity: no object within reach
    };
    Line out, back;
    double minBendRadius = 0.0;      ///< the material's (0: none or an angle limit)
    double clearanceThreshold = 0.0; ///< the sweep's (0: collisions only)
};
/// The series of hose `hose` (index into report.hoses) from the report's per-step series.
MotionPlotSeries plotSeries(const exporting::SweepReport& report, const formats::Project& project,
                            size_t hose);

/// A limit a hose breaks somewhere in a sweep, named where it happens.
struct SweepFinding
{
    std::string hoseId;
    int step = -1;              ///< index into SweepReport::steps
    std::vector<double> values; ///< the motion values at that step (one per motion)
    int firstPoint = -1;        ///< axis points concerned (−1: the whole hose)
    int lastPoint = -1;
    std::string sceneId; ///< a clearance finding: the object
    std::string objectPath;
    /// "pillar to carriage — sweep, lever at 0.0°, carriage at 0.0 mm: 32.0 mm from
    /// /motion-rig/base_plate (clearance 40.0 mm), on 51 of 51 steps": the hose, the motion
    /// values where it is worst, what, and on how many of the sweep's steps.
    std::string text;
};
/// Every limit broken in the sweep (HoseSweep::violates): stretch beyond the band, a bend
/// beyond its limit, an attachment beyond reach, an object nearer than the threshold or a
/// collision; each at the step where it is worst, in project hose order.
std::vector<SweepFinding> sweepFindings(const exporting::SweepReport& report,
                                        const formats::Project& project);

} // namespace chaintube::editor
