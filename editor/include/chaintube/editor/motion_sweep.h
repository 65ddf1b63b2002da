// ChainTube editor — the Motions dock's rules without Qt: slider ticks of a project motion, how
// a motion value is written, and the findings and plot series of a motion sweep
// (exporting::sweepMotions, the same sweep as `chaintube check --sweep`).
#pragma once

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

} // namespace chaintube::editor
