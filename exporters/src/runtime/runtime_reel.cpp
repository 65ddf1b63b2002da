// HoseRuntime's reel: paying a running hose out of a reel and reeling it in, its bookkeeping
// (attachments, grabbable points, clips, the description) and where the skin's joints go once
// the point count changed.
#include "chaintube/export/runtime.h"
#include "runtime_internal.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace chaintube::rig {

using detail::hoseOutOfRangeText;
using detail::restArcs;
using detail::runningHoseName;

namespace {
ReelResult reelRefused(std::string message)
{
    ReelResult result;
    result.status = Status::InvalidInput;
    result.message = std::move(message);
    return result;
}

/// The description's per-point arrays as the running hose is now (after a reel changed its
/// point count): axis, rest lengths and the joints' limits, as the exporter writes them.
void describeShape(RigHose& description, const Hose& hose)
{
    description.axis = hose.points();
    description.restLengths.clear();
    for (int s = 0; s < hose.segmentCount(); ++s)
        description.restLengths.push_back(hose.restLength(s));
    description.jointBendLimits.clear();
    description.jointMinBendRadii.clear();
    for (int j = 1; j + 1 < hose.pointCount(); ++j) {
        const double limit = hose.deflectionLimit(j);
        description.jointBendLimits.push_back(limit);
        if (hose.material().bendLimit.kind == BendLimit::Kind::MinBendRadius &&
            limit < 3.141592653589793)
            description.jointMinBendRadii.push_back(hose.material().bendLimit.value);
        else
            description.jointMinBendRadii.push_back(
                bendRadiusOfTurn(0.5 * (hose.restLength(j - 1) + hose.restLength(j)), limit));
    }
}
} // namespace

std::pair<int, int> HoseRuntime::outletPoint(const RunningHose& running, const ReelOutlet& outlet,
                                             const RigHose& description)
{
    const int side = outlet.end == HoseEnd::Start ? +1 : -1;
    if (outlet.clip < ReelOutlet::kEnd) return {-1, side};
    const Hose& hose = running.hose;
    const int endPoint = outlet.end == HoseEnd::Start ? 0 : hose.pointCount() - 1;
    const int clipId =
        outlet.clip >= 0 && static_cast<size_t>(outlet.clip) < description.clips.size()
            ? running.clipIds[static_cast<size_t>(outlet.clip)]
            : -1;
    for (const Hose::Attachment& a : hose.attachments()) {
        const bool isOutlet = outlet.clip >= 0
                                  ? a.id == clipId
                                  : !a.isClip() && endPoint >= a.first && endPoint <= a.last;
        if (isOutlet) return {side > 0 ? a.last : a.first, side};
    }
    return {-1, side};
}

double HoseRuntime::jointPlace(const RunningHose& running, size_t joint,
                               const std::vector<double>& arcs, double outletArc, int side)
{
    double place = running.jointArc[joint];
    // A joint beyond the outlet that the reel took in waits at the outlet.
    if (running.jointBeyond[joint] && !std::isnan(outletArc))
        place = side > 0 ? std::max(place, outletArc) : std::min(place, outletArc);
    return std::clamp(place, 0.0, arcs.back());
}

ReelResult HoseRuntime::reel(int hose, HoseEnd end, double length, double minLength,
                             double maxLength)
{
    return reelAt(hose, ReelOutlet{ReelOutlet::kEnd, end}, length, minLength, maxLength);
}

ReelResult HoseRuntime::reelThroughClip(int hose, int clip, HoseEnd drumEnd, double length,
                                        double minLength, double maxLength)
{
    if (hose >= 0 && hose < hoseCount()) {
        const RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
        if (clip < 0 || static_cast<size_t>(clip) >= d.clips.size())
            return reelRefused("clip " + std::to_string(clip) + " is out of range: hose " +
                               std::to_string(hose) + " (\"" + d.id + "\") has " +
                               std::to_string(d.clips.size()) + " clips");
    }
    return reelAt(hose, ReelOutlet{clip, drumEnd}, length, minLength, maxLength);
}

ReelResult HoseRuntime::reelAt(int hose, ReelOutlet outlet, double length, double minLength,
                               double maxLength)
{
    if (hose < 0 || hose >= hoseCount()) return reelRefused(hoseOutOfRangeText(hose, hoseCount()));
    RunningHose& running = m_hoses[static_cast<size_t>(hose)];
    RigHose& d = m_descriptor.hoses[static_cast<size_t>(hose)];
    const std::string name = runningHoseName(hose, d);
    if (d.isStatic) return reelRefused(name + " is static: its length never changes");

    // Before the call: where the joints are and where the outlet is.
    const std::vector<double> arcsBefore = restArcs(running.hose);
    const std::pair<int, int> outletBefore = outletPoint(running, outlet, d);
    const int before = outletBefore.first, side = outletBefore.second; // a lambda captures them
    const int pointsBefore = running.hose.pointCount();
    const auto [previousOutlet, previousSide] = outletPoint(running, running.reelOutlet, d);
    const double previousOutletArc =
        previousOutlet >= 0 ? arcsBefore[static_cast<size_t>(previousOutlet)] : std::nan("");
    std::vector<double> slidesBefore;
    for (size_t c = 0; c < d.clips.size(); ++c)
        slidesBefore.push_back(clip(hose, static_cast<int>(c)).slide);

    ReelResult result =
        outlet.clip >= 0
            ? chaintube::reelThroughClip(running.hose,
                                         running.clipIds[static_cast<size_t>(outlet.clip)],
                                         outlet.end, length, minLength, maxLength)
            : chaintube::reel(running.hose, outlet.end, length, minLength, maxLength);
    if (result.status == Status::InvalidInput) {
        result.message = name + ": " + result.message;
        return result;
    }
    if (result.paid == 0.0) { // nothing changed; a reel that could not pay is in the frame
        UpdateResult frame = result.update;
        if (result.status == Status::Clamped && frame.status == Status::Ok)
            frame.status = Status::Clamped;
        combine(running.pendingResult, frame);
        return result;
    }
    if (before < 0) throw std::logic_error(name + ": the reel's outlet is not on the hose");

    // The skin's joints: from the first reel on, placed by rest arc length. A new outlet first
    // fixes them where they are posed (by the previous outlet), then splits them into the drum
    // side and the side beyond the outlet; the latter keep their distance from the far end.
    if (running.reelOutlet.clip == ReelOutlet::kNever) {
        const size_t joints = std::min(d.jointNodes.size(), arcsBefore.size());
        running.jointArc.assign(arcsBefore.begin(),
                                arcsBefore.begin() + static_cast<std::ptrdiff_t>(joints));
        running.jointBeyond.assign(joints, 0);
    }
    if (!(running.reelOutlet == outlet)) {
        const double outletArc = arcsBefore[static_cast<size_t>(before)];
        for (size_t j = 0; j < running.jointArc.size(); ++j) {
            running.jointArc[j] =
                jointPlace(running, j, arcsBefore, previousOutletArc, previousSide);
            running.jointBeyond[j] =
                side > 0 ? running.jointArc[j] > outletArc : running.jointArc[j] < outletArc;
        }
        running.reelOutlet = outlet;
    }
    for (size_t j = 0; j < running.jointArc.size(); ++j)
        if ((side > 0) == (running.jointBeyond[j] != 0)) running.jointArc[j] += result.paid;

    // Point indices beyond the change moved by the points added or removed there.
    const int delta = running.hose.pointCount() - pointsBefore;
    const auto shifted = [&](int point) {
        const bool moves = side > 0 ? point > before : point >= before;
        return moves ? std::clamp(point + delta, 0, running.hose.pointCount() - 1) : point;
    };
    for (LiveAttachment& a : running.live) {
        if (a.attached) {
            for (const Hose::Attachment& now : running.hose.attachments())
                if (now.id == a.id) {
                    a.firstPoint = now.first;
                    a.lastPoint = now.last;
                }
        } else {
            a.firstPoint = shifted(a.firstPoint);
            a.lastPoint = shifted(a.lastPoint);
        }
    }
    findGrabbable(running, d);
    describeShape(d, running.hose);
    for (RigAttachment& a : d.attachments) {
        a.firstPoint = shifted(a.firstPoint);
        a.lastPoint = shifted(a.lastPoint);
    }
    for (size_t c = 0; c < d.clips.size(); ++c) {
        const Hose::Attachment& held = clip(hose, static_cast<int>(c));
        d.clips[c].place += held.slide - slidesBefore[c];
        d.clips[c].slideMin = held.slideMin;
        d.clips[c].slideMax = held.slideMax;
    }
    d.grabbablePoints = running.grabbable;

    UpdateResult frame = result.update;
    if (result.status == Status::Clamped && frame.status == Status::Ok)
        frame.status = Status::Clamped;
    combine(running.pendingResult, frame);
    return result;
}

} // namespace chaintube::rig
