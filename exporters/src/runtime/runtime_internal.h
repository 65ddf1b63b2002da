// What HoseRuntime's source files share (runtime.cpp, runtime_reel.cpp): the actions' refusal
// texts and the rest arc lengths of a hose.
#pragma once

#include "chaintube/export/rig_descriptor.h"
#include "chaintube/hose.h"

#include <string>
#include <vector>

namespace chaintube::rig::detail {

/// The refusal texts the runtime's actions share.
inline std::string hoseOutOfRangeText(int hose, int count)
{
    return "hose " + std::to_string(hose) + " is out of range: expected 0 to " +
           std::to_string(count - 1);
}
inline std::string badEndText(int end)
{
    return "end " + std::to_string(end) +
           ": expected 0 (the first point's end) or 1 (the last point's)";
}
inline std::string runningHoseName(int hose, const RigHose& d)
{
    return "hose " + std::to_string(hose) + " (\"" + d.id + "\")";
}

/// Rest arc length from point 0 to each point.
inline std::vector<double> restArcs(const Hose& hose)
{
    std::vector<double> arcs(static_cast<size_t>(hose.pointCount()), 0.0);
    for (int s = 0; s < hose.segmentCount(); ++s)
        arcs[static_cast<size_t>(s) + 1] = arcs[static_cast<size_t>(s)] + hose.restLength(s);
    return arcs;
}

} // namespace chaintube::rig::detail
