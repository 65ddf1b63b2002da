// Clips: attachments the hose slides through (Hose::addClip; lib/README.md, "Clips").
#include "chaintube/hose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace chaintube {

namespace {
/// Bisection steps of one slide decision (each O(pinned points of the two sides)).
constexpr int kSlideBisections = 48;

std::string clipNumber(double value)
{
    std::ostringstream out;
    out.precision(15);
    out << value;
    return out.str();
}

/// Σ of `lengths` before each index: prefix[k] = lengths[0] + … + lengths[k − 1].
std::vector<double> prefixSums(const std::vector<double>& lengths)
{
    std::vector<double> prefix(lengths.size() + 1, 0.0);
    for (size_t s = 0; s < lengths.size(); ++s)
        prefix[s + 1] = prefix[s] + lengths[s];
    return prefix;
}

/// The segment j with prefix[j] ≤ s ≤ prefix[j + 1], within [lo, hi].
int segmentAt(const std::vector<double>& prefix, double s, int lo, int hi)
{
    const int j =
        static_cast<int>(std::upper_bound(prefix.begin(), prefix.end(), s) - prefix.begin()) - 1;
    return std::clamp(j, lo, hi);
}

/// Smallest s in [a, b] with f(s) ≥ 0 for f(a) < 0 (b when f(b) < 0); bisection.
template <typename F> double firstNonNegative(F f, double a, double b)
{
    if (f(b) < 0.0) return b;
    for (int k = 0; k < kSlideBisections && b - a > 1e-15 * std::max(1.0, std::abs(b)); ++k) {
        const double m = 0.5 * (a + b);
        (f(m) < 0.0 ? a : b) = m;
    }
    return b;
}

/// One side of a clip: the pinned points it must reach, nearest first, ending at an anchor
/// (a run of two or more fixed points) or at its last pinned point; none: a free side.
struct Side
{
    std::vector<Vec3> pins;
    double polyline = 0.0; ///< length of the polyline through pins
    int far = -1;          ///< index of the farthest pin
    bool free() const { return pins.empty(); }
};

} // namespace

const char* toString(Hold hold)
{
    switch (hold) {
    case Hold::Fixed:
        return "fixed";
    case Hold::Sliding:
        return "sliding";
    case Hold::SlidingTurning:
        return "sliding-turning";
    }
    return "unknown";
}

int Hose::addClip(double place, const Frame& frame, const ClipOptions& options)
{
    if (options.hold == Hold::Fixed)
        throw InvalidArgument("clip hold: expected sliding or sliding-turning (a fixed hold is "
                              "an attachment: attach())");
    if (!isFiniteFrame(frame))
        throw InvalidArgument("clip frame: expected a finite translation and a unit rotation");
    const double total = restLengthTotal();
    if (!std::isfinite(options.slideMin) || options.slideMin < 0.0 ||
        std::isnan(options.slideMax) || options.slideMax < options.slideMin)
        throw InvalidArgument("clip end stops: expected 0 <= slideMin <= slideMax, got " +
                              clipNumber(options.slideMin) + " … " + clipNumber(options.slideMax));
    const double lo = options.slideMin, hi = std::min(total, options.slideMax);
    if (!std::isfinite(place) || place < lo || place > hi)
        throw InvalidArgument("clip place: expected a rest arc length in " + clipNumber(lo) +
                              " … " + clipNumber(hi) + " m, got " + clipNumber(place));
    const std::vector<double> prefix = prefixSums(m_restLength);
    int j = segmentAt(prefix, place, 0, segmentCount() - 1);
    if (place == prefix[static_cast<size_t>(j)] && j > 0 &&
        (m_fixed[static_cast<size_t>(j)] || m_fixed[static_cast<size_t>(j + 1)]))
        --j; // a place on a point: the segment before it when the one after is taken
    for (const int i : {j, j + 1})
        if (m_fixed[static_cast<size_t>(i)])
            throw InvalidArgument("clip place " + clipNumber(place) + " m: point " +
                                  std::to_string(i) +
                                  " of the segment holding it is already fixed by an attachment");
    const Vec3 a = m_local[static_cast<size_t>(j)], b = m_local[static_cast<size_t>(j + 1)];
    const double length = (b - a).norm();
    if (!(length > 0.0))
        throw InvalidArgument("clip place " + clipNumber(place) + " m: segment " +
                              std::to_string(j) + " has no direction (zero length)");
    const double f =
        (place - prefix[static_cast<size_t>(j)]) / m_restLength[static_cast<size_t>(j)];
    Attachment clip;
    clip.id = m_nextAttachmentId++;
    clip.first = j;
    clip.last = j + 1;
    clip.frame = frame;
    clip.hold = options.hold;
    const Vec3 axis = (b - a) / length;
    clip.clipCentre = frame.applyInverse(m_origin + a + (f * length) * axis);
    clip.clipAxis = (frame.rotation.conjugate() * axis).normalized();
    clip.slide = place;
    clip.slideMin = lo;
    clip.slideMax = hi;
    // Its two points where they are now (the segment's current length): nothing moves.
    clip.localPoints = {frame.applyInverse(m_origin + a), frame.applyInverse(m_origin + b)};
    m_fixed[static_cast<size_t>(j)] = m_fixed[static_cast<size_t>(j + 1)] = 1;
    m_attachments.push_back(std::move(clip));
    m_edgePoint = -1;
    return m_attachments.back().id;
}

void Hose::placeClip(Attachment& a, double s)
{
    const std::vector<double> prefix = prefixSums(m_restLength);
    auto taken = [&](int i) {
        return m_fixed[static_cast<size_t>(i)] && (i < a.first || i > a.last);
    };
    int j = segmentAt(prefix, s, 0, segmentCount() - 1);
    if (j > 0 && s == prefix[static_cast<size_t>(j)] && (taken(j) || taken(j + 1))) --j;
    // The points the slide passed through the clip lie on its axis at their rest distance from
    // the centre (the hose runs straight through it): the new segment's two and those between
    // it and the old one. A start for the spans on both sides.
    const Vec3 centre = a.frame.apply(a.clipCentre) - m_origin;
    const Vec3 axis = a.frame.rotation * a.clipAxis;
    for (int k = std::min(a.first, j); k <= std::max(a.last, j + 1); ++k)
        m_local[static_cast<size_t>(k)] = centre + (prefix[static_cast<size_t>(k)] - s) * axis;
    for (int i = a.first; i <= a.last; ++i)
        m_fixed[static_cast<size_t>(i)] = 0;
    a.first = j;
    a.last = j + 1;
    m_fixed[static_cast<size_t>(j)] = m_fixed[static_cast<size_t>(j + 1)] = 1;
    const double rest = m_restLength[static_cast<size_t>(j)];
    const double f = std::clamp((s - prefix[static_cast<size_t>(j)]) / rest, 0.0, 1.0);
    a.localPoints = {a.clipCentre - (f * rest) * a.clipAxis,
                     a.clipCentre + ((1.0 - f) * rest) * a.clipAxis};
    a.slide = s;
    for (int i = 0; i < 2; ++i)
        m_local[static_cast<size_t>(j + i)] =
            a.frame.apply(a.localPoints[static_cast<size_t>(i)]) - m_origin;
}

std::vector<int> Hose::slideClips(int held, const Vec3* heldTarget, double margin,
                                  const std::vector<std::pair<int, double>>* shifts)
{
    std::vector<int> slid;
    std::vector<Attachment*> clips;
    for (Attachment& a : m_attachments)
        if (a.isClip()) clips.push_back(&a);
    if (clips.empty()) return slid;
    std::sort(clips.begin(), clips.end(), [](auto* x, auto* y) { return x->first < y->first; });
    const int n = pointCount();
    const std::vector<double> restBefore = prefixSums(m_restLength);
    const std::vector<double> reachBefore = prefixSums(m_maxLength);
    // Where a pinned point must be: its attachment's frame puts it, the held point at its
    // target.
    auto owner = [&](int i) -> const Attachment* {
        for (const Attachment& a : m_attachments)
            if (i >= a.first && i <= a.last) return &a;
        return nullptr;
    };
    auto pinPosition = [&](int i) -> Vec3 {
        if (i == held) return heldTarget ? *heldTarget : m_local[static_cast<size_t>(i)];
        const Attachment* a = owner(i);
        return a->frame.apply(a->localPoints[static_cast<size_t>(i - a->first)]) - m_origin;
    };
    for (Attachment* clip : clips) {
        // A clip moved along its own axis slides along the hose, which stays where it is (no
        // friction): its slide starts from where the centre's move along the axis takes it.
        double shift = 0.0;
        if (shifts)
            for (const auto& [id, along] : *shifts)
                if (id == clip->id) shift = along;
        auto pinnedOther = [&](int i) {
            return i == held ||
                   (m_fixed[static_cast<size_t>(i)] && (i < clip->first || i > clip->last));
        };
        // The pinned points nearest the clip on each side bound where it can slide.
        int q1 = -1, q2 = n;
        for (int i = clip->first - 1; i >= 0 && q1 < 0; --i)
            if (pinnedOther(i)) q1 = i;
        for (int i = clip->last + 1; i < n && q2 == n; ++i)
            if (pinnedOther(i)) q2 = i;
        const int jlo = q1 + 1, jhi = q2 - 2;
        if (jlo > jhi) continue;
        const double sLo = std::max(clip->slideMin, restBefore[static_cast<size_t>(jlo)]);
        const double sHi = std::min(clip->slideMax, restBefore[static_cast<size_t>(jhi + 1)]);
        if (!(sLo <= sHi)) continue;
        auto collect = [&](int from, int step) {
            Side side;
            for (int i = from; i >= 0 && i < n; i += step) {
                if (!pinnedOther(i)) continue;
                const Vec3 at = pinPosition(i);
                if (!side.pins.empty()) side.polyline += (at - side.pins.back()).norm();
                side.pins.push_back(at);
                side.far = i;
                const Attachment* a = i == held ? nullptr : owner(i);
                if (a && a->last > a->first) break; // an anchor: the span ends here
            }
            return side;
        };
        const Side before = collect(q1, -1), after = collect(q2, +1);
        const Vec3 centre = clip->frame.apply(clip->clipCentre) - m_origin;
        const Vec3 axis = (clip->frame.rotation * clip->clipAxis).normalized();
        // A side's straight-line demand (through its pins from the clip's segment) and its reach
        // with the clip's centre at s; a free side demands nothing.
        auto demandAndReach = [&](double s, bool first) -> std::pair<double, double> {
            const Side& side = first ? before : after;
            if (side.free()) return {0.0, std::numeric_limits<double>::infinity()};
            const int j = segmentAt(restBefore, s, jlo, jhi);
            const double rest = m_restLength[static_cast<size_t>(j)];
            const double f = std::clamp((s - restBefore[static_cast<size_t>(j)]) / rest, 0.0, 1.0);
            const Vec3 end =
                first ? Vec3(centre - (f * rest) * axis) : Vec3(centre + ((1.0 - f) * rest) * axis);
            const double reach = first ? reachBefore[static_cast<size_t>(j)] -
                                             reachBefore[static_cast<size_t>(side.far)]
                                       : reachBefore[static_cast<size_t>(side.far)] -
                                             reachBefore[static_cast<size_t>(j + 1)];
            return {(end - side.pins.front()).norm() + side.polyline, reach};
        };
        // Spare length (< 0: the side wants more) and whether a side is short: its demand
        // within half the margin of its reach.
        auto spare = [&](double s, bool first) {
            const auto [demand, reach] = demandAndReach(s, first);
            return std::isinf(reach) ? reach : (1.0 - margin) * reach - demand;
        };
        auto isShort = [&](double s, bool first) {
            const auto [demand, reach] = demandAndReach(s, first);
            return demand > (1.0 - 0.5 * margin) * reach;
        };
        // A short side is fed until the full margin is restored, from the other side's spare
        // (never below that side's own margin). Both short, or the other side with nothing to
        // spare: the clip holds like a fixed one and the update decides as usual.
        const double s0 = std::clamp(clip->slide + (std::isfinite(shift) ? shift : 0.0), sLo, sHi);
        double s = s0;
        const bool short1 = isShort(s0, true), short2 = isShort(s0, false);
        if (short1 && !short2 && spare(s0, false) > 0.0) {
            s = std::min(firstNonNegative([&](double t) { return spare(t, true); }, s0, sHi),
                         firstNonNegative([&](double t) { return -spare(t, false); }, s0, sHi));
        } else if (short2 && !short1 && spare(s0, true) > 0.0) {
            s = -std::min(firstNonNegative([&](double t) { return spare(-t, false); }, -s0, -sLo),
                          firstNonNegative([&](double t) { return -spare(-t, true); }, -s0, -sLo));
        }
        if (s != clip->slide) {
            placeClip(*clip, s);
            slid.push_back(clip->id);
        }
    }
    return slid;
}

} // namespace chaintube
