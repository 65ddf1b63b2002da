#include "chaintube/tension.h"

#include <algorithm>
#include <cmath>

namespace chaintube {

namespace {

/// The pinned point nearest to `from` in direction `step` (+1 or −1) along the hose, excluding
/// `from`'s own attachment: −1 when the hose ends free first.
int nextPin(const Hose& hose, int from, int step, int ownId)
{
    for (int i = from + step; i >= 0 && i < hose.pointCount(); i += step) {
        if (i == hose.heldPoint()) return i;
        for (const Hose::Attachment& a : hose.attachments())
            if (a.id != ownId && i >= a.first && i <= a.last) return i;
    }
    return -1;
}

struct PullSide
{
    Vec3 pull = Vec3::Zero(); ///< tautness · strain (floored) · unit direction
    double tautness = 0.0;
    double strain = 0.0;
    double forcePerStiffness = 0.0;
};

PullSide pullSideOf(const Hose& hose, const Hose::Attachment& own, int step)
{
    PullSide side;
    const int start = step > 0 ? own.last : own.first;
    const int end = nextPin(hose, start, step, own.id);
    if (end < 0) return side; // a free end: slack
    const int lo = std::min(start, end), hi = std::max(start, end);
    double rest = 0.0;
    for (int s = lo; s < hi; ++s)
        rest += hose.restLength(s);
    if (!(rest > 0.0)) return side;
    const double chord = (hose.point(end) - hose.point(start)).norm();
    double gap = 0.0;
    for (const Hose::Attachment& a : hose.attachments())
        if (a.id == own.id || (end >= a.first && end <= a.last))
            gap = std::max(gap, std::max(0.0, hose.attachmentGap(a.id)));
    side.tautness =
        gap > 1e-9
            ? 1.0
            : std::clamp((chord - (1.0 - kTautWindow) * rest) / (kTautWindow * rest), 0.0, 1.0);
    side.strain = std::max(0.0, chord - rest) / rest + gap / rest;
    const Vec3 first = hose.point(start + step) - hose.point(start);
    const double length = first.norm();
    if (side.tautness > 0.0 && length > 0.0) {
        side.pull = (side.tautness * std::max(side.strain, kTautStrainFloor) / length) * first;
        side.forcePerStiffness = side.tautness * side.strain;
    }
    return side;
}

} // namespace

Vec3 AttachmentPull::force(double axialStiffness) const
{
    if (!(axialStiffness >= 0.0) || !std::isfinite(axialStiffness)) return Vec3::Zero();
    return axialStiffness * pullPerStiffness;
}

AttachmentPull attachmentPull(const Hose& hose, int id)
{
    AttachmentPull result;
    const auto& all = hose.attachments();
    const auto own =
        std::find_if(all.begin(), all.end(), [&](const auto& a) { return a.id == id; });
    if (own == all.end()) return result;
    Vec3 pull = Vec3::Zero();
    for (const int step : {-1, +1}) {
        if ((step < 0 && own->first == 0) || (step > 0 && own->last == hose.pointCount() - 1))
            continue;
        const PullSide side = pullSideOf(hose, *own, step);
        pull += side.pull;
        result.tautness = std::max(result.tautness, side.tautness);
        if (side.tautness > 0.0) result.strain = std::max(result.strain, side.strain);
        const double length = side.pull.norm();
        if (length > 0.0) result.pullPerStiffness += (side.forcePerStiffness / length) * side.pull;
    }
    const double norm = pull.norm();
    if (norm > 0.0 && std::isfinite(norm)) result.direction = pull / norm;
    if (!result.pullPerStiffness.allFinite()) result.pullPerStiffness.setZero();
    return result;
}

} // namespace chaintube
