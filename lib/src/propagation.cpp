#include "propagation.h"

#include "span_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

namespace chaintube {

namespace {

constexpr double kLengthTolerance = 1e-12; // relative, when deciding whether to correct

/// Solver::bowFlatCompressedSpans: samples of the buckling mode along its chord, and at most
/// this many Newton steps for its amplitude (from above it takes 3–8; each is one pass over
/// the samples).
constexpr int kBowSamples = 512;
constexpr int kBowSteps = 32;

/// The buckling mode's height over its amplitude at sample q, (1 − cos 2πq/N) / 2 for N =
/// kBowSamples: the same for every span (the curve at amplitude a over chord c is
/// (c q/N, a · height[q])).
const std::array<double, kBowSamples + 1>& bowHeights()
{
    static const std::array<double, kBowSamples + 1> heights = [] {
        std::array<double, kBowSamples + 1> h{};
        for (size_t q = 0; q <= kBowSamples; ++q)
            h[q] = 0.5 *
                   (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(q) / kBowSamples));
        return h;
    }();
    return heights;
}

using detail::anyPerpendicular;

} // namespace

[[gnu::always_inline]] inline bool Solver::place(int i, int a, const Vec3* incoming,
                                                 const Vec3& anchorOld, Vec3& direction)
{
    Vec3 placed;
    return place<false>(i, a, Vec3(p[static_cast<size_t>(a)]), incoming, anchorOld, direction,
                        placed);
}

template <bool Fma>
[[gnu::always_inline]] inline bool Solver::place(int i, int a, const Vec3 anchor,
                                                 const Vec3* incoming, const Vec3& anchorOld,
                                                 Vec3& direction, Vec3& placed)
{
    const size_t seg = static_cast<size_t>(std::min(i, a));
    const double lmin = h.m_minLength[seg], lmax = h.m_maxLength[seg];
    Vec3& point = p[static_cast<size_t>(i)];
    Vec3 d = point - anchor;
    double length2 = d.squaredNorm();
    bool moved = false;
    double length = 0.0;
    Vec3 v;
    // The direction the bend correction works from: d itself (not the unit v, which waits
    // for the square root and the division; the correction only needs d's part
    // perpendicular to the incoming direction, so it starts as soon as d is known).
    Vec3 along = d;
    double along2 = length2;
    double inverse2 = 0.0; // 1/|d|² when v is d's own direction
    bool turned = false;
    if (!(length2 > 1e-24 * lmin * lmin)) {
        // Dragged onto its neighbour: keep the direction the segment had before the move.
        Vec3 before = point - anchorOld;
        if (!(before.squaredNorm() > 1e-24 * lmin * lmin))
            before = incoming ? *incoming : Vec3::UnitX();
        v = before.normalized();
        along = v;
        along2 = 1.0;
        moved = true;
    } else {
        // 1/|d| as sqrt(|d|²) · (1/|d|²): the square root and the division run in
        // parallel instead of one after the other (the sweep is latency bound).
        length = std::sqrt(length2);
        inverse2 = 1.0 / length2;
        v = d * (length * inverse2);
    }
    if (incoming) {
        const size_t joint = static_cast<size_t>(a);
        const double cosLimit = h.m_cosLimit[joint], sinLimit = h.m_sinLimit[joint];
        // |v − u|² = 4 sin²(φ/2) keeps full precision for small turns, where the cosine
        // is too flat to decide; the limit carries its tolerance (see recomputeLimits).
        // (A branch: the processor predicts it, so the corrected direction below does not
        // wait for v.)
        if ((v - *incoming).squaredNorm() > h.m_chordLimit2[joint]) {
            const double c = incoming->dot(along);
            Vec3 w = along - c * *incoming;
            const double wn2 = w.squaredNorm();
            // 1/|w| as sqrt(|w|²) · (1/|w|²): both in parallel (this is on the chain).
            double wnInverse = std::sqrt(wn2) * (1.0 / wn2);
            if (!(wn2 > 1e-24 * along2)) {
                // Fold-back: take the bend plane from where the point was.
                w = (point - anchorOld) - (point - anchorOld).dot(*incoming) * *incoming;
                const double wn = w.norm();
                wnInverse = 1.0 / wn;
                if (!(wn > 1e-12 * lmin)) {
                    w = anyPerpendicular(*incoming);
                    wnInverse = 1.0;
                }
            }
            v = cosLimit * *incoming + (sinLimit * wnInverse) * w;
            // Unit to rounding; but along a long run of joints all at their limit (a tail
            // falling from far off) each one carries the last one's rounding on and grows
            // it (by 10 % a joint at 400 points): such a direction is normalised again.
            const double v2 = v.squaredNorm();
            if (!(std::abs(v2 - 1.0) <= 1e-14)) v *= 1.0 / std::sqrt(v2);
            moved = true;
            turned = true;
        }
    }
    if (!turned && inverse2 > 0.0) {
        // Only stretched or compressed along d: p = anchor + d · (L/|d|) with
        // L/|d| = (L/|d|²)·|d|, one multiply after the square root (L/|d|² waits only for
        // the division, which runs beside it) instead of three in a row.
        double scale = 0.0;
        if (length < lmin * (1.0 - kLengthTolerance)) {
            scale = (lmin * inverse2) * length;
            moved = true;
        } else if (length > lmax * (1.0 + kLengthTolerance)) {
            scale = (lmax * inverse2) * length;
            moved = true;
        }
        if (moved) point = alongFrom<Fma>(anchor, scale, d);
        placed = point;
        direction = v;
        return moved;
    }
    double target = length;
    if (length < lmin * (1.0 - kLengthTolerance)) {
        target = lmin;
        moved = true;
    } else if (length > lmax * (1.0 + kLengthTolerance)) {
        target = lmax;
        moved = true;
    }
    if (moved) point = alongFrom<Fma>(anchor, target, v);
    placed = point;
    direction = v;
    return moved;
}

template <bool Fma>
[[gnu::always_inline]] inline Vec3 Solver::alongFrom(const Vec3& anchor, double scale,
                                                     const Vec3& w)
{
    if constexpr (Fma)
        return Vec3(__builtin_fma(scale, w.x(), anchor.x()),
                    __builtin_fma(scale, w.y(), anchor.y()),
                    __builtin_fma(scale, w.z(), anchor.z()));
    else
        return anchor + scale * w;
}

template <bool Fma> [[gnu::always_inline]] inline void Solver::advance(Solver::Sweep& s)
{
    const int i = s.next;
    if (i < 0 || i >= h.pointCount()) {
        s.active = false;
        return;
    }
    if (pinned(i)) {
        hitPin = true;
        s.active = false;
        return;
    }
    const Vec3 before = p[static_cast<size_t>(i)];
    Vec3 direction;
    const bool moved = place<Fma>(i, i - s.step, s.anchor, s.haveIncoming ? &s.incoming : nullptr,
                                  s.anchorOld, direction, s.anchor);
    movedPoints += moved;
    if (!moved && !s.anchorMoved && !fullSweep) {
        s.active = false;
        return;
    }
    s.incoming = direction;
    s.haveIncoming = true;
    s.anchorMoved = moved;
    s.anchorOld = before;
    s.next = i + s.step;
}

template <bool Fma>
[[gnu::always_inline]] inline void Solver::runSweeps(Solver::Sweep leftIn, Solver::Sweep rightIn)
{
    // Local copies whose address never escapes: the compiler keeps them in registers.
    Sweep left = leftIn, right = rightIn;
    while (left.active && right.active) {
        advance<Fma>(left);
        advance<Fma>(right);
    }
    while (left.active)
        advance<Fma>(left);
    while (right.active)
        advance<Fma>(right);
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("fma"))) void Solver::runSweepsFma(const Solver::Sweep& left,
                                                         const Solver::Sweep& right)
{
    runSweeps<true>(left, right);
}

#endif
void Solver::run(Solver::Sweep left, Solver::Sweep right)
{
    const int n = h.pointCount();
    for (Sweep* s : {&left, &right}) {
        const int a = s->next - s->step;
        if (s->active && a >= 0 && a < n) s->anchor = p[static_cast<size_t>(a)];
    }
#if defined(__x86_64__) && defined(__GNUC__)
    static const bool fma = __builtin_cpu_supports("fma");
    if (fma) return runSweepsFma(left, right);
#endif
    runSweeps<false>(left, right);
}

void Solver::propagateFromRun(int first, int last, const Vec3& oldFirst, const Vec3& oldLast)
{
    const int n = h.pointCount();
    const int left = first - 1, right = last + 1;
    const bool leftFree = left >= 0 && !pinned(left);
    const bool rightFree = right < n && !pinned(right);
    // Direction arriving at `first` when sweeping left: from last (or the pinned right
    // neighbour) to first.
    auto unitFrom = [&](int from, int to) {
        return Vec3((p[static_cast<size_t>(to)] - p[static_cast<size_t>(from)]).normalized());
    };
    const bool leftHasIncoming = first < last || (right < n && !rightFree);
    const bool rightHasIncoming = first < last || (left >= 0 && !leftFree);
    Vec3 leftDirection, rightDirection;
    Vec3 leftBefore = leftFree ? p[static_cast<size_t>(left)] : Vec3::Zero();
    Vec3 rightBefore = rightFree ? p[static_cast<size_t>(right)] : Vec3::Zero();

    if (leftFree && rightFree && first == last) {
        // A single pinned point with two free neighbours (a grab): fix both lengths, then
        // split any excess bend at the point symmetrically between the neighbours.
        place(left, first, nullptr, oldFirst, leftDirection);
        place(right, first, nullptr, oldFirst, rightDirection);
        balanceJoint(first, leftDirection, rightDirection, leftBefore, rightBefore);
        ++movedPoints;
        run(Sweep{left - 1, -1, leftDirection, true, true, leftBefore, true},
            Sweep{right + 1, +1, rightDirection, true, true, rightBefore, true});
        return;
    }
    Sweep leftSweep{left, -1, Vec3::Zero(), leftHasIncoming, true, oldFirst, leftFree};
    Sweep rightSweep{right, +1, Vec3::Zero(), rightHasIncoming, true, oldLast, rightFree};
    if (leftFree && leftHasIncoming) leftSweep.incoming = unitFrom(first + 1, first);
    if (rightFree && rightHasIncoming) rightSweep.incoming = unitFrom(last - 1, last);
    if (!leftFree && left >= 0) hitPin = true;
    if (!rightFree && right < n) hitPin = true;
    run(leftSweep, rightSweep);
}

void Solver::balanceJoint(int k, Vec3& leftDirection, Vec3& rightDirection, const Vec3& leftBefore,
                          const Vec3& rightBefore)
{
    const size_t j = static_cast<size_t>(k);
    const Vec3 in = -leftDirection; // direction of the segment arriving at k
    const Vec3 out = rightDirection;
    if ((out - in).squaredNorm() <= h.m_chordLimit2[j]) return;
    Vec3 mean = in + out;
    if (!(mean.norm() > 1e-12)) {
        // Full fold at k: use the old chord between the neighbours as the mean direction.
        mean = rightBefore - leftBefore;
        if (!(mean.norm() > 1e-12 * h.m_minLength[j])) mean = anyPerpendicular(out);
    }
    mean.normalize();
    Vec3 across = out - out.dot(mean) * mean;
    if (!(across.norm() > 1e-12)) across = anyPerpendicular(mean);
    across.normalize();
    const double ch = h.m_cosHalfLimit[j], sh = h.m_sinHalfLimit[j];
    rightDirection = ch * mean + sh * across;
    leftDirection = -(ch * mean - sh * across);
    const double leftLength = (p[j - 1] - p[j]).norm();
    const double rightLength = (p[j + 1] - p[j]).norm();
    p[j - 1] = p[j] + leftLength * leftDirection;
    p[j + 1] = p[j] + rightLength * rightDirection;
}

void Solver::sweepTails(int lo, int hi, const std::vector<Vec3>& before, bool full)
{
    const int n = h.pointCount();
    fullSweep = full;
    Sweep left{lo - 1, -1, Vec3::Zero(), false, true, before[static_cast<size_t>(lo)], lo - 1 >= 0};
    Sweep right{hi + 1, +1, Vec3::Zero(), false, true, before[static_cast<size_t>(hi)], hi + 1 < n};
    if (left.active && lo + 1 < n) {
        left.incoming = (p[static_cast<size_t>(lo)] - p[static_cast<size_t>(lo + 1)]).normalized();
        left.haveIncoming = left.incoming.allFinite();
    }
    if (right.active && hi - 1 >= 0) {
        right.incoming = (p[static_cast<size_t>(hi)] - p[static_cast<size_t>(hi - 1)]).normalized();
        right.haveIncoming = right.incoming.allFinite();
    }
    run(left, right);
    fullSweep = false;
}

bool Solver::bowFlatCompressedSpans(std::vector<Vec3>& before)
{
    if (h.m_attachments.empty()) return false; // a grabbed point alone bounds no span
    thread_local std::vector<std::pair<int, int>> pins;
    pins.clear();
    for (const Hose::Attachment& a : h.m_attachments)
        pins.emplace_back(a.first, a.last);
    if (grabbed >= 0) pins.emplace_back(grabbed, grabbed);
    std::sort(pins.begin(), pins.end());
    bool bowed = false;
    for (size_t r = 1; r < pins.size(); ++r) {
        const int first = pins[r - 1].second, i = pins[r].first;
        if (i <= first + 1) continue;
        const Vec3 start = p[static_cast<size_t>(first)], chord = p[static_cast<size_t>(i)] - start;
        const double minimum = h.m_minLengthBefore[static_cast<size_t>(i)] -
                               h.m_minLengthBefore[static_cast<size_t>(first)];
        const double c = chord.norm();
        // A span whose pins coincide has no line to bow from: left to the relaxation.
        if (!(c > 1e-9 * minimum) || !(c < minimum * (1.0 - 1e-9))) continue;
        const Vec3 axis = chord / c;
        bool flat = true;
        for (int k = first + 1; k < i && flat; ++k) {
            const Vec3 d = p[static_cast<size_t>(k)] - start;
            flat = (d - d.dot(axis) * axis).norm() <= 1e-9 * minimum;
        }
        if (!flat) continue;
        const Vec3 up = anyPerpendicular(axis); // the fold-back rule's plane (place())
        // The first buckling mode of a rod clamped at both ends, y(x) = a (1 − cos 2πx/c)/2:
        // it leaves and meets both pins along the line, so the pins' own tangents (an
        // attachment's segments) stay compatible. The amplitude a gives the sampled curve
        // the span's rest length; the points are laid at its rest lengths along the curve.
        double total = 0.0;
        for (int s = first; s < i; ++s)
            total += h.m_restLength[static_cast<size_t>(s)];
        const std::array<double, kBowSamples + 1>& height = bowHeights();
        const double dx = c / kBowSamples;
        auto curve = [&](double a, size_t q) {
            return Vec2(dx * static_cast<double>(q), a * height[q]);
        };
        // The sampled curve's length L(a) is convex and increasing in a ≥ 0 (a sum of
        // sqrt(dx² + a² Δh²)), and L(a) ≥ sqrt(c² + 4a²) (the heights rise by 1 and fall by
        // 1): Newton's method from a = sqrt(total² − c²)/2, where L ≥ total, comes down to the
        // root monotonically; it stops where a step no longer lowers a (the rounding floor).
        double amplitude = 0.5 * std::sqrt(std::max(0.0, total * total - c * c));
        for (int step = 0; step < kBowSteps; ++step) {
            double length = 0.0, slope = 0.0;
            for (size_t q = 0; q < kBowSamples; ++q) {
                const double rise = height[q + 1] - height[q];
                const double piece = std::sqrt(dx * dx + amplitude * amplitude * rise * rise);
                length += piece;
                slope += amplitude * rise * rise / piece;
            }
            if (!(length > total) || !(slope > 0.0)) break;
            const double next = amplitude - (length - total) / slope;
            if (!(next < amplitude)) break;
            amplitude = std::max(0.0, next);
        }
        if (!bowed) before = p;
        bowed = true;
        double along = 0.0, wanted = 0.0;
        size_t q = 0;
        Vec2 previous = curve(amplitude, 0);
        for (int k = first + 1; k < i; ++k) {
            wanted += h.m_restLength[static_cast<size_t>(k - 1)];
            Vec2 next = curve(amplitude, q + 1);
            while (along + (next - previous).norm() < wanted && q + 1 < kBowSamples) {
                along += (next - previous).norm();
                previous = next;
                ++q;
                next = curve(amplitude, q + 1);
            }
            const double piece = (next - previous).norm();
            const Vec2 at = piece > 0.0
                                ? Vec2(previous + (next - previous) * ((wanted - along) / piece))
                                : next;
            p[static_cast<size_t>(k)] = start + at.x() * axis + at.y() * up;
        }
    }
    return bowed;
}

} // namespace chaintube
