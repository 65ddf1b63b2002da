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

} // namespace chaintube::editor
