// Reeling a hose in and paying it out (chaintube/reel.h).
#include "chaintube/reel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace chaintube {

namespace {
/// A call is done in steps of at most this fraction of the segment rest length, at most
/// kReelMaxSteps of them: a step changes the reel segment by less than a split or merge needs.
constexpr double kReelStepFraction = 0.5;
constexpr int kReelMaxSteps = 64;
/// A reel segment that a step would leave shorter than this fraction of the segment rest length
/// merges with its outer neighbour (no sliver stays at the outlet); one whose outer point is
/// pinned stops there until the merged segment fits between the two pins.
constexpr double kReelFloorFraction = 1e-3;

std::string reelNumber(double value)
{
    std::ostringstream out;
    out.precision(15);
    out << value;
    return out.str();
}

ReelResult reelRejected(std::string message)
{
    ReelResult result;
    result.status = Status::InvalidInput;
    result.message = std::move(message);
    return result;
}
} // namespace

const char* toString(HoseEnd end)
{
    return end == HoseEnd::Start ? "start" : "end";
}

namespace detail {

/// The reel's work on a Hose's private state (a friend of Hose).
class ReelAccess
{
public:
    /// The outlet: a pinned point, and the side (+1: higher indices) its free hose is on.
    struct Outlet
    {
        int point = 0;
        int side = 1;
    };

    static ReelResult run(Hose& h, Outlet outlet, double length, double minLength,
                          double maxLength);

private:
    struct Step
    {
        double paid = 0.0;
        int added = 0;
        int removed = 0;
        double largestMove = 0.0;
        int iterations = 0;
        std::string refused; ///< why nothing (or less) was paid
    };
    static Step step(Hose& h, Outlet& outlet, double delta);
    /// The hose's segment rest length at the reel: the reel segment's outer neighbour's; with
    /// none, the longest other segment's; with none either, HoseSpec::segmentLength.
    static double segmentUnit(const Hose& h, Outlet outlet);
    static void shiftAttachments(Hose& h, int from, int by);
};

double ReelAccess::segmentUnit(const Hose& h, Outlet outlet)
{
    const int seg = outlet.side > 0 ? outlet.point : outlet.point - 1;
    const int neighbour = seg + outlet.side;
    if (neighbour >= 0 && neighbour < h.segmentCount())
        return h.m_restLength[static_cast<size_t>(neighbour)];
    double longest = 0.0;
    for (int s = 0; s < h.segmentCount(); ++s)
        if (s != seg) longest = std::max(longest, h.m_restLength[static_cast<size_t>(s)]);
    return longest > 0.0 ? longest : h.m_spec.segmentLength;
}

void ReelAccess::shiftAttachments(Hose& h, int from, int by)
{
    for (Hose::Attachment& a : h.m_attachments)
        if (a.first >= from) {
            a.first += by;
            a.last += by;
        }
    if (h.m_held >= from) h.m_held += by;
}

ReelAccess::Step ReelAccess::step(Hose& h, Outlet& outlet, double delta)
{
    Step out;
    const int o = outlet.point, side = outlet.side;
    const int seg = side > 0 ? o : o - 1; // the reel segment
    const int r = o + side;               // its outer point (free)
    const int neighbour = seg + side;     // the segment beyond it, if any
    const bool hasNeighbour = neighbour >= 0 && neighbour < h.segmentCount();
    const double rest = h.m_restLength[static_cast<size_t>(seg)];
    const double unit = segmentUnit(h, outlet);
    const double e = h.m_spec.material.expansionCoefficient;
    const double oldTotal = h.restLengthTotal();

    const Hose saved = h; // a step that fails is undone
    const std::vector<Vec3> oldPoints = h.m_local;
    const Vec3 po = h.m_local[static_cast<size_t>(o)];
    // A free tail beyond the outlet (nothing fixed or held up to the hose's end) moves rigidly
    // with the reel segment's outer point: every length and every bend beyond it stays as it is.
    bool freeTail = true;
    for (int i = r; i >= 0 && i < h.pointCount(); i += side)
        freeTail = freeTail && !h.m_fixed[static_cast<size_t>(i)] && i != h.m_held;
    // It is first moved rigidly; reeling in, where that leaves a joint beyond its limit, and
    // after a merge, only the reel segment's outer point is placed and the rest follows it.
    bool rigidTail = freeTail;
    Vec3 shifted = Vec3::Zero();
    const auto moveOuter = [&](int from, const Vec3& by) {
        shifted = by;
        for (int i = from; i >= 0 && i < h.pointCount(); i += side)
            if ((rigidTail || i == from) && !h.m_fixed[static_cast<size_t>(i)])
                h.m_local[static_cast<size_t>(i)] += by;
    };

    // The change, decided before any point moves: grow / shrink the reel segment, or merge it.
    bool merge = false;
    double paid = delta;
    if (delta < 0.0 && rest + delta < 0.5 * unit) {
        if (hasNeighbour) {
            const int q = r + side;
            const Vec3 chord = h.m_local[static_cast<size_t>(q)] - po;
            const double c = chord.norm();
            const double merged = rest + h.m_restLength[static_cast<size_t>(neighbour)] + delta;
            const double placed = std::clamp(c, merged * (1.0 - e), merged * (1.0 + e));
            const bool qFixed = h.m_fixed[static_cast<size_t>(q)] != 0;
            // A merge moves the new outer point by |placed − c| ≤ |delta| once the reel segment
            // is no longer than |delta| (c ≥ the neighbour's length − rest), sooner where the
            // joint beyond the outlet is nearly straight; a sliver below the floor merges anyway.
            merge = c > 0.0 && (qFixed ? std::abs(placed - c) <= 1e-12 * merged
                                       : std::abs(placed - c) <= -delta * (1.0 + 1e-9) ||
                                             rest + delta < kReelFloorFraction * unit);
        }
        if (!merge) {
            const double floor =
                hasNeighbour ? kReelFloorFraction * unit : kReelStepFraction * unit;
            paid = std::min(0.0, std::max(delta, floor - rest)); // no farther than the floor
            if (paid > delta)
                out.refused = hasNeighbour
                                  ? "the segment at the outlet ends at a pinned point that a "
                                    "merge would move"
                                  : "the last segment beyond the outlet is at half its rest "
                                    "length";
            if (paid == 0.0) return out;
        }
    }

    std::vector<Vec3> before; // the new indexing's positions before the pass
    int insertedAt = -1, removedAt = -1;
    if (merge) {
        rigidTail = false;
        const int q = r + side;
        const double merged = rest + h.m_restLength[static_cast<size_t>(neighbour)] + paid;
        Vec3 u = h.m_local[static_cast<size_t>(q)] - po;
        const double c = u.norm();
        u /= c;
        const double placed = std::clamp(c, merged * (1.0 - e), merged * (1.0 + e));
        moveOuter(q, po + placed * u - h.m_local[static_cast<size_t>(q)]);
        const int keep = std::min(seg, neighbour);
        h.m_restLength[static_cast<size_t>(keep)] = merged;
        h.m_restLength.erase(h.m_restLength.begin() + std::max(seg, neighbour));
        h.m_local.erase(h.m_local.begin() + r);
        h.m_fixed.erase(h.m_fixed.begin() + r);
        removedAt = r;
        if (h.m_held == r) h.m_held = -1;
        shiftAttachments(h, r + 1, -1);
        if (side < 0) outlet.point = o - 1;
        out.removed = 1;
    } else {
        const double grown = rest + paid;
        Vec3 u = h.m_local[static_cast<size_t>(r)] - po;
        const double c = u.norm();
        u = c > 0.0 ? Vec3(u / c) : Vec3(Vec3::UnitX()); // a zero segment: not from a valid hose
        const double placed = std::clamp(c + paid, grown * (1.0 - e), grown * (1.0 + e));
        moveOuter(r, po + placed * u - h.m_local[static_cast<size_t>(r)]);
        h.m_restLength[static_cast<size_t>(seg)] = grown;
        if (grown > 1.5 * unit) { // split: a point on the segment, `unit` from its outer point
            const double inner = grown - unit;
            const Vec3 at = po + (placed * inner / grown) * u;
            const int ins = side > 0 ? o + 1 : o;
            h.m_local.insert(h.m_local.begin() + ins, at);
            h.m_fixed.insert(h.m_fixed.begin() + ins, 0);
            if (side > 0) {
                h.m_restLength[static_cast<size_t>(seg)] = inner;
                h.m_restLength.insert(h.m_restLength.begin() + seg + 1, unit);
            } else {
                h.m_restLength[static_cast<size_t>(seg)] = inner;
                h.m_restLength.insert(h.m_restLength.begin() + seg, unit);
            }
            insertedAt = ins;
            shiftAttachments(h, ins, +1);
            if (side < 0) outlet.point = o + 1;
            out.added = 1;
        }
    }

    // Clips past the change along the hose (rest arc lengths from point 0) move with it.
    const double newTotal = oldTotal + paid;
    for (Hose::Attachment& a : h.m_attachments) {
        if (!a.isClip()) continue;
        const bool after = side > 0 ? a.first > outlet.point : a.first >= outlet.point;
        if (after) {
            a.slide += paid;
            a.slideMin += paid;
            a.slideMax += paid;
        }
        a.slideMin = std::clamp(a.slideMin, 0.0, newTotal);
        a.slideMax = a.slideMax >= oldTotal ? newTotal : std::min(a.slideMax, newTotal);
    }

    const size_t n = h.m_local.size();
    // The old positions in the new indexing (the inserted point where it was placed).
    before.resize(n);
    for (size_t i = 0, k = 0; i < n; ++i) {
        if (static_cast<int>(i) == insertedAt) {
            before[i] = h.m_local[i];
            continue;
        }
        if (static_cast<int>(k) == removedAt) ++k;
        before[i] = oldPoints[k++];
    }
    h.recomputeLimits();
    int iterations = 0;
    // A free tail moved rigidly is valid unless a joint's limit changed with the reel
    // segment's length (a bend limit from a minimum bend radius): the paper's pass then turns
    // the tail into the limit, moving its points by more than the translation.
    bool rigid = rigidTail && h.measureViolation().status == Status::Ok;
    if (rigidTail && !rigid && delta < 0.0) {
        // A limit tightened with the reel segment: the tail follows its outer point instead.
        for (int i = r + side; i >= 0 && i < h.pointCount(); i += side)
            h.m_local[static_cast<size_t>(i)] -= shifted;
    }
    const bool closed = rigid || h.closeSpans(h.m_held, before, iterations);
    double largest = 0.0;
    for (size_t i = 0, k = 0; i < n; ++i) {
        if (static_cast<int>(i) == insertedAt) continue;
        if (static_cast<int>(k) == removedAt) ++k;
        largest = std::max(largest, (h.m_local[i] - oldPoints[k++]).norm());
    }
    if (!closed || h.measureViolation().status != Status::Ok ||
        largest > kReelMoveFactor * std::abs(paid) * (1.0 + 1e-9) + 1e-12) {
        h = saved;
        outlet.point = o;
        Step refused;
        refused.iterations = iterations;
        refused.refused = !closed
                              ? "the span beyond the outlet cannot take the length change"
                              : "the shape would move a point farther than the length paid allows";
        return refused;
    }
    out.paid = paid;
    out.largestMove = largest;
    out.iterations = iterations;
    if (out.added || out.removed) {
        h.m_workingSet.assign(3 * n, 0);
        h.m_gravityPrevious.clear(); // step(): no velocity across a changed point count
        h.m_gravityLast.clear();
    }
    h.m_trustCarry = Hose::TrustCarry{};
    h.m_edgePoint = -1;
    h.m_settledRevision = 0; // step(): the hose may fall again
    h.m_dirtyViolation = false;
    ++h.m_revision;
    return out;
}

ReelResult ReelAccess::run(Hose& h, Outlet outlet, double length, double minLength,
                           double maxLength)
{
    const int r = outlet.point + outlet.side;
    if (r < 0 || r >= h.pointCount() || h.m_fixed[static_cast<size_t>(r)])
        return reelRejected("reel outlet at point " + std::to_string(outlet.point) +
                            ": expected a free point beyond it, point " + std::to_string(r) +
                            (r < 0 || r >= h.pointCount() ? " does not exist" : " is fixed"));
    ReelResult result;
    const double total = h.restLengthTotal();
    const double allowed =
        length > 0.0 ? std::max(0.0, maxLength - total) : std::max(0.0, total - minLength);
    double want = std::copysign(std::min(std::abs(length), allowed), length);
    if (std::abs(want) < std::abs(length)) {
        result.clamped = true;
        result.message =
            length > 0.0 ? "the rest length reached its maximum " + reelNumber(maxLength) + " m"
                         : "the rest length reached its minimum " + reelNumber(minLength) + " m";
    }
    double paid = 0.0;
    for (int k = 0; k < kReelMaxSteps && want != 0.0; ++k) {
        const double unit = segmentUnit(h, outlet);
        const double delta =
            std::copysign(std::min(std::abs(want), kReelStepFraction * unit), want);
        const Step done = step(h, outlet, delta);
        paid += done.paid;
        want -= done.paid;
        result.segmentsAdded += done.added;
        result.segmentsRemoved += done.removed;
        result.largestMove += done.largestMove; // steps add up: a bound on the call's moves
        result.update.iterations += done.iterations;
        if (done.paid != delta) {
            if (done.paid == 0.0 || !done.refused.empty()) {
                result.clamped = true;
                result.message = done.refused;
                break;
            }
        }
        if (std::abs(want) <= 1e-15 * std::max(1.0, total)) want = 0.0;
    }
    if (want != 0.0 && !result.clamped) {
        result.clamped = true;
        result.message = "more than " + std::to_string(kReelMaxSteps) + " steps in one call";
    }
    result.paid = paid;
    const UpdateResult state = h.measureViolation();
    const int iterations = result.update.iterations;
    result.update = state;
    result.update.iterations = iterations;
    result.status = result.clamped ? Status::Clamped : Status::Ok;
    return result;
}

} // namespace detail

namespace {
std::string reelBoundsProblem(double length, double minLength, double maxLength)
{
    if (!std::isfinite(length))
        return "reel length: expected a finite length in metres, got " + reelNumber(length);
    if (!std::isfinite(minLength) || minLength < 0.0)
        return "reel minLength: expected a finite length >= 0 m, got " + reelNumber(minLength);
    if (std::isnan(maxLength) || maxLength < minLength)
        return "reel maxLength: expected a length >= minLength (" + reelNumber(minLength) +
               " m), got " + reelNumber(maxLength);
    return {};
}
} // namespace

ReelResult reel(Hose& hose, HoseEnd end, double length, double minLength, double maxLength)
{
    if (std::string problem = reelBoundsProblem(length, minLength, maxLength); !problem.empty())
        return reelRejected(std::move(problem));
    const int endPoint = end == HoseEnd::Start ? 0 : hose.pointCount() - 1;
    const Hose::Attachment* fixing = nullptr;
    for (const Hose::Attachment& a : hose.attachments())
        if (!a.isClip() && endPoint >= a.first && endPoint <= a.last) fixing = &a;
    if (!fixing)
        return reelRejected(std::string("reel end ") + toString(end) + " (point " +
                            std::to_string(endPoint) +
                            "): expected an end fixed by an attachment (the reel's outlet)");
    if (length == 0.0) {
        ReelResult nothing;
        nothing.update = hose.measureViolation();
        return nothing;
    }
    detail::ReelAccess::Outlet outlet;
    outlet.point = end == HoseEnd::Start ? fixing->last : fixing->first;
    outlet.side = end == HoseEnd::Start ? +1 : -1;
    return detail::ReelAccess::run(hose, outlet, length, minLength, maxLength);
}

ReelResult reelThroughClip(Hose& hose, int clipId, HoseEnd drumEnd, double length, double minLength,
                           double maxLength)
{
    if (std::string problem = reelBoundsProblem(length, minLength, maxLength); !problem.empty())
        return reelRejected(std::move(problem));
    const Hose::Attachment* clip = nullptr;
    for (const Hose::Attachment& a : hose.attachments())
        if (a.id == clipId) clip = &a;
    if (!clip || !clip->isClip())
        return reelRejected("reel clip " + std::to_string(clipId) + ": expected the id of a clip" +
                            (clip ? " (it is a fixed attachment)" : " (no such id)"));
    if (length == 0.0) {
        ReelResult nothing;
        nothing.update = hose.measureViolation();
        return nothing;
    }
    detail::ReelAccess::Outlet outlet;
    outlet.point = drumEnd == HoseEnd::Start ? clip->last : clip->first;
    outlet.side = drumEnd == HoseEnd::Start ? +1 : -1;
    return detail::ReelAccess::run(hose, outlet, length, minLength, maxLength);
}

} // namespace chaintube
