// The ChainTube axis solver: the paper's outward propagation (phase 1) and, only when a
// propagation runs into a fixed point, alternating sweeps between the pinned points (phase 2)
// with a clamp of infeasible grabs.
#include "chaintube/hose.h"

#include "banded_ldlt.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace chaintube {

namespace {
constexpr double kLengthTolerance = 1e-12;   // relative, when deciding whether to correct
constexpr double kConvergedLength = 1e-10;   // relative, phase 2 success
constexpr int kMaxSweeps = 200;
constexpr double kMomentum = 0.9;
constexpr int kStallWindow = 32; // give up when a window of sweeps gains less than half
constexpr int kBisectionSteps = 16;

Vec3 anyPerpendicular(const Vec3& u)
{
    const Vec3 a = u.cwiseAbs();
    Vec3 axis = Vec3::UnitX();
    if (a.y() <= a.x() && a.y() <= a.z()) axis = Vec3::UnitY();
    else if (a.z() <= a.x() && a.z() <= a.y()) axis = Vec3::UnitZ();
    return u.cross(axis).normalized();
}

} // namespace

class Solver
{
public:
    explicit Solver(Hose& hose) : h(hose), p(hose.m_local) {}

    /// Place p[i] relative to its already-final anchor p[a] (a = i ± 1). `incoming` is the unit
    /// direction of the segment arriving at the anchor along the sweep (null: no angle check,
    /// the anchor is an end or its other neighbour is not settled). `anchorOld` is where the
    /// anchor was before this update, for the degenerate fallbacks. Returns whether p[i] moved;
    /// `direction` receives the unit direction anchor → p[i].
    [[gnu::always_inline]] inline bool place(int i, int a, const Vec3* incoming, const Vec3& anchorOld,
                                             Vec3& direction)
    {
        Vec3 placed;
        return place<false>(i, a, Vec3(p[static_cast<size_t>(a)]), incoming, anchorOld, direction, placed);
    }

    /// As above with the anchor's final position passed in (a sweep carries it in registers:
    /// reading it back from memory would put a store-to-load forward on the critical path).
    /// With Fma, the final multiply-add is fused (only instantiated in FMA-targeted code).
    template <bool Fma>
    [[gnu::always_inline]] inline bool place(int i, int a, const Vec3 anchor, const Vec3* incoming,
                                             const Vec3& anchorOld, Vec3& direction, Vec3& placed)
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

    /// anchor + scale · w, the multiply-add fused with Fma (only instantiated in FMA-targeted
    /// code).
    template <bool Fma>
    [[gnu::always_inline]] static inline Vec3 alongFrom(const Vec3& anchor, double scale, const Vec3& w)
    {
        if constexpr (Fma)
            return Vec3(__builtin_fma(scale, w.x(), anchor.x()), __builtin_fma(scale, w.y(), anchor.y()),
                        __builtin_fma(scale, w.z(), anchor.z()));
        else
            return anchor + scale * w;
    }

    bool pinned(int i) const { return h.m_fixed[static_cast<size_t>(i)] != 0 || i == grabbed; }

    /// One outward sweep of the paper's propagation: from point `next` towards `step` (±1)
    /// until an end, a pinned point, or two consecutive unmoved points.
    struct Sweep
    {
        int next = 0;
        int step = 1;
        Vec3 incoming = Vec3::Zero(); ///< unit direction arriving at the anchor next − step
        bool haveIncoming = false;
        bool anchorMoved = true;
        Vec3 anchorOld = Vec3::Zero();
        bool active = true;
        Vec3 anchor = Vec3::Zero(); ///< final position of point next − step (set by run())
    };

    template <bool Fma>
    [[gnu::always_inline]] inline void advance(Sweep& s)
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
        const bool moved = place<Fma>(i, i - s.step, s.anchor, s.haveIncoming ? &s.incoming : nullptr, s.anchorOld,
                                 direction, s.anchor);
        movedPoints += moved;
        if (!moved && !s.anchorMoved) {
            s.active = false;
            return;
        }
        s.incoming = direction;
        s.haveIncoming = true;
        s.anchorMoved = moved;
        s.anchorOld = before;
        s.next = i + s.step;
    }

    /// Runs two independent sweeps interleaved: their dependency chains overlap in the CPU.
    template <bool Fma>
    [[gnu::always_inline]] inline void runSweeps(Sweep leftIn, Sweep rightIn)
    {
        // Local copies whose address never escapes: the compiler keeps them in registers.
        Sweep left = leftIn, right = rightIn;
        while (left.active && right.active) {
            advance<Fma>(left);
            advance<Fma>(right);
        }
        while (left.active) advance<Fma>(left);
        while (right.active) advance<Fma>(right);
    }
#if defined(__x86_64__) && defined(__GNUC__)
    __attribute__((target("fma"))) void runSweepsFma(const Sweep& left, const Sweep& right)
    {
        runSweeps<true>(left, right);
    }
#endif

    void run(Sweep left, Sweep right)
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

    /// The paper's update after the run first … last was placed (grab: first = last = k).
    /// `old` holds the run's positions before the move (for fallbacks).
    void propagateFromRun(int first, int last, const Vec3& oldFirst, const Vec3& oldLast)
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

    /// Bend at point k between k−1 and k+1 above its limit: rotate both neighbours about p[k]
    /// in their common plane, each by half the excess (paper Fig. 8).
    void balanceJoint(int k, Vec3& leftDirection, Vec3& rightDirection, const Vec3& leftBefore,
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

    /// Largest violation near the boundaries of pinned runs: after a backward sweep these are
    /// the only places a constraint can still be violated (every free point was placed against
    /// its neighbour). Length excess is relative, turn excess in radians.
    double boundaryViolation(const std::vector<int>& boundaries) const
    {
        const int n = h.pointCount();
        double worst = 0.0;
        for (int b : boundaries) {
            for (int s = std::max(0, b - 2); s <= std::min(n - 2, b + 1); ++s) {
                const size_t k = static_cast<size_t>(s);
                const double length = (p[k + 1] - p[k]).norm();
                worst = std::max(worst, std::max(length - h.m_maxLength[k], h.m_minLength[k] - length) /
                                            h.m_restLength[k]);
            }
            for (int j = std::max(1, b - 2); j <= std::min(n - 2, b + 2); ++j)
                worst = std::max(worst, h.turnExcess(static_cast<size_t>(j), p));
        }
        return worst;
    }

    /// Phase 2: alternate forward and backward sweeps over the whole axis, skipping pinned
    /// points, until every constraint holds, kMaxSweeps is reached, or progress stalls. The
    /// sweeps converge linearly (about half the violation a round); on an inextensible hose,
    /// once it is below 1e-3, a Gauss-Newton projection (newtonFinish) is tried, again every 6
    /// rounds while it fails: feasible grabs between pins in ~10 rounds + 1–3 steps instead of
    /// 30–60 rounds. Not in
    /// the clamps' bisection trials (`newton` false there): which trials succeed stays the
    /// sweeps' decision, so a clamp does not flip on a 1e-8 input difference (the runtime's
    /// float frames; tested by the runtime round trip).
    bool relax()
    {
#if defined(__x86_64__) && defined(__GNUC__)
        static const bool fma = __builtin_cpu_supports("fma");
        if (fma) return relaxFma();
#endif
        return relaxWith<false>();
    }
#if defined(__x86_64__) && defined(__GNUC__)
    __attribute__((target("fma"))) bool relaxFma() { return relaxWith<true>(); }
#endif

    template <bool Fma>
    [[gnu::always_inline]] inline bool relaxWith()
    {
        const int n = h.pointCount();
        std::vector<int> boundaries;
        for (int i = 0; i < n; ++i) {
            if (!pinned(i)) continue;
            const bool freeBefore = i > 0 && !pinned(i - 1);
            const bool freeAfter = i + 1 < n && !pinned(i + 1);
            if (freeBefore || freeAfter || i == grabbed || (i > 0 && runOf(i - 1) != runOf(i)))
                boundaries.push_back(i);
        }
        std::vector<double> history;
        std::vector<Vec3> previous = p;
        // Momentum (heavy-ball extrapolation of the free points between rounds, with adaptive
        // restart): FABRIK-style alternation converges linearly and slowly on nearly taut or
        // bend-limited spans (rates of 0.67 … 0.91 per round measured on 20- and 100-point spans
        // pulled between two fixed ends). Carrying 0.9 of the last round's motion forward, and
        // dropping it for one round whenever the violation grows, cut those cases ~10x. The
        // sweeps restore every constraint; the state returned is never an extrapolated one.
        const double momentum = kMomentum;
        // The Newton finish on inextensible hoses only: every length is then an equality and
        // the projection nearly always lands (1,210 of 1,248 tries in the ends-fixed scenario);
        // with a stretch band the active set changes under each step and it mostly does not
        // (108 of 1,533 on BM_GrabBetweenFixedEnds, 5 % dearer), so the sweeps finish alone.
        int nextNewton = h.m_spec.material.expansionCoefficient == 0.0 ? 0 : kMaxSweeps;
        for (int iteration = 0; iteration < kMaxSweeps; ++iteration) {
            for (int pass = 0; pass < 2; ++pass) {
                const int step = pass == 0 ? +1 : -1;
                const int begin = pass == 0 ? 1 : n - 2;
                // The direction place() returns for a point is the next point's incoming
                // direction (no second normalisation of the same segment).
                // The placed position is the next anchor, kept in registers (no store-to-load
                // forward on the chain).
                Vec3 carried = Vec3::Zero(), anchor = Vec3::Zero();
                int carriedFor = -1;
                for (int i = begin; i >= 0 && i < n; i += step) {
                    if (pinned(i)) continue;
                    const int a = i - step;
                    const int before = a - step;
                    Vec3 incoming;
                    const bool haveIncoming = before >= 0 && before < n;
                    if (carriedFor != a) {
                        anchor = p[static_cast<size_t>(a)];
                        if (haveIncoming) incoming = (anchor - p[static_cast<size_t>(before)]).normalized();
                    } else {
                        incoming = carried;
                    }
                    place<Fma>(i, a, anchor, haveIncoming ? &incoming : nullptr, anchor, carried, anchor);
                    carriedFor = i;
                }
            }
            const double violation = boundaryViolation(boundaries);
            if (violation <= kConvergedLength) return true;
            if (newton && violation < 1e-3 && iteration >= nextNewton) {
                if (newtonFinish()) return true;
                nextNewton = iteration + 6;
            }
            const bool restart = !history.empty() && violation > history.back();
            for (int i = 0; i < n; ++i) {
                if (pinned(i)) continue;
                const size_t k = static_cast<size_t>(i);
                const Vec3 now = p[k];
                if (!restart) p[k] += momentum * (now - previous[k]);
                previous[k] = now;
            }
            history.push_back(violation);
            if (history.size() > kStallWindow &&
                history.back() > 0.5 * history[history.size() - 1 - kStallWindow])
                return false; // stalled: the request is (numerically) out of reach
        }
        return false;
    }

    /// Gauss-Newton projection onto the active constraints (lengths outside their band or at a
    /// fixed length, bends at or beyond their limit as a minimum distance between the joint's
    /// neighbours), minimal-norm steps through a banded LDLᵀ of J Jᵀ (detail::solveBandedLdlt,
    /// as the gravity rounds); at most 3 steps. Keeps the result only if every constraint then
    /// holds to kConvergedLength (measured in full), otherwise restores the state it started
    /// from.
    bool newtonFinish()
    {
        const int n = h.pointCount();
        thread_local std::vector<Vec3> backup;
        struct Constraint
        {
            int a, b;
            Vec3 u;
            double c;
        };
        thread_local std::vector<Constraint> cs;
        thread_local std::vector<double> band, rhs;
        backup = p;
        constexpr int kBand = 6;
        auto isFree = [&](int i) { return !pinned(i); };
        for (int step = 0; step < 3; ++step) {
            cs.clear();
            for (int i = 0; i + 1 < n; ++i) {
                // Length of segment i, then the bend at i + 1 (a distance from i to i + 2).
                if (isFree(i) || isFree(i + 1)) {
                    const size_t k = static_cast<size_t>(i);
                    const Vec3 d = p[k + 1] - p[k];
                    const double length = d.norm();
                    const double lmin = h.m_minLength[k], lmax = h.m_maxLength[k];
                    double target = length;
                    if (length >= lmax * (1.0 - 1e-12)) target = lmax;
                    else if (length <= lmin * (1.0 + 1e-12)) target = lmin;
                    // (A segment of no length has no direction: left to the sweeps.)
                    if (length > 0.0 && (target != length || lmin == lmax))
                        cs.push_back({i, i + 1, d / length, length - target});
                }
                if (i + 2 < n && (isFree(i) || isFree(i + 2))) {
                    const size_t k = static_cast<size_t>(i);
                    const Vec3 in = p[k + 1] - p[k], out = p[k + 2] - p[k + 1], d = p[k + 2] - p[k];
                    const double a = in.norm(), b = out.norm(), distance = d.norm();
                    const double minimum2 = a * a + b * b + 2.0 * a * b * h.m_cosLimit[k + 1];
                    const double minimum = std::sqrt(std::max(0.0, minimum2));
                    if (distance <= minimum * (1.0 + 1e-9) && distance > 0.0)
                        cs.push_back({i, i + 2, d / distance, std::min(0.0, distance - minimum)});
                }
            }
            const size_t m = cs.size();
            if (m == 0) break;
            band.assign(m * (kBand + 1), 0.0);
            rhs.resize(m);
            auto shared = [&](const Constraint& x, const Constraint& y) {
                double v = 0.0;
                for (int px : {x.a, x.b})
                    for (int py : {y.a, y.b})
                        if (px == py && isFree(px)) v += (px == x.a ? -1.0 : 1.0) * (py == y.a ? -1.0 : 1.0) * x.u.dot(y.u);
                return v;
            };
            for (size_t i = 0; i < m; ++i) {
                rhs[i] = -cs[i].c;
                for (size_t j = i; j < m && j <= i + kBand; ++j) band[i * (kBand + 1) + (j - i)] = shared(cs[i], cs[j]);
                band[i * (kBand + 1)] += 1e-12;
            }
            // A dependent row (no unique step) leaves the state to the sweeps.
            if (detail::solveBandedLdlt(band.data(), rhs.data(), m, kBand + 1) > 0) {
                p = backup;
                return false;
            }
            for (size_t i = 0; i < m; ++i) {
                const Constraint& x = cs[i];
                if (isFree(x.a)) p[static_cast<size_t>(x.a)] -= rhs[i] * x.u;
                if (isFree(x.b)) p[static_cast<size_t>(x.b)] += rhs[i] * x.u;
            }
        }
        bool finite = true;
        for (const Vec3& x : p) finite = finite && x.allFinite();
        const UpdateResult v = finite ? h.measureViolation() : UpdateResult{};
        if (finite && v.lengthViolation <= kConvergedLength && v.angleViolation <= kConvergedLength) return true;
        p = backup;
        return false;
    }

    /// Clamp of a grab whose point k has fixed points on one side only (pinSide = −1: left,
    /// +1: right) and a free end on the other: FABRIK-style reaching. Alternately place the
    /// chain from the target back towards the nearest pinned point, then from the pinned point
    /// out to the free end with k free. Every pass from the pin leaves all constraints exact;
    /// k converges to the reachable position closest to the target. Bounded: 64 rounds.
    void softClamp(int k, const Vec3& target, int pinSide)
    {
        const int n = h.pointCount();
        int pin = k + pinSide;
        while (!h.m_fixed[static_cast<size_t>(pin)]) pin += pinSide;
        const int freeEnd = pinSide < 0 ? n - 1 : 0;
        const int outward = -pinSide; // from the pin towards the free end
        auto direction = [&](int from, int to) {
            return Vec3((p[static_cast<size_t>(to)] - p[static_cast<size_t>(from)]).normalized());
        };
        auto valid = [&](int i) { return i >= 0 && i < n; };
        Vec3 previous = p[static_cast<size_t>(k)];
        for (int round = 0; round < 64; ++round) {
            // Towards the pin from the target (k pinned at the target).
            p[static_cast<size_t>(k)] = target;
            for (int i = k + pinSide; i != pin; i += pinSide) {
                const int anchor = i - pinSide, before = anchor - pinSide;
                const bool haveIncoming = valid(before);
                Vec3 incoming = haveIncoming ? direction(before, anchor) : Vec3::Zero(), out;
                place(i, anchor, haveIncoming ? &incoming : nullptr, p[static_cast<size_t>(anchor)], out);
            }
            // From the pin out to the free end, k free.
            for (int i = pin + outward; valid(i) && i != freeEnd + outward; i += outward) {
                const int anchor = i - outward, before = anchor - outward;
                const bool haveIncoming = valid(before);
                Vec3 incoming = haveIncoming ? direction(before, anchor) : Vec3::Zero(), out;
                place(i, anchor, haveIncoming ? &incoming : nullptr, p[static_cast<size_t>(anchor)], out);
            }
            const double step = (p[static_cast<size_t>(k)] - previous).norm();
            previous = p[static_cast<size_t>(k)];
            if (step <= 1e-12 * h.m_restLength[0] * n) break;
        }
    }

    /// Attachment id owning point i (0 for the grabbed point or a free point).
    int runOf(int i) const
    {
        for (const Hose::Attachment& a : h.m_attachments)
            if (i >= a.first && i <= a.last) return a.id;
        return 0;
    }

    bool solveAfterPlacement(const std::pair<int, int>* runs, const std::pair<Vec3, Vec3>* oldEnds,
                             size_t count)
    {
        // A straight span pushed shorter than it can compress: every sweep would keep it on its
        // line, so it is bowed before anything else; if the bowed state does not solve, the
        // request is decided as without the bow, from the straight state.
        std::vector<Vec3> flat;
        if (bowFlatCompressedSpans(flat)) {
            const bool hitPinBefore = hitPin;
            hitPin = true; // the bow moved points the propagation may not reach
            if (solve(runs, oldEnds, count)) return true;
            p = std::move(flat);
            hitPin = hitPinBefore;
            movedPoints = 0;
        }
        return solve(runs, oldEnds, count);
    }

    bool solve(const std::pair<int, int>* runs, const std::pair<Vec3, Vec3>* oldEnds, size_t count)
    {
        for (size_t r = 0; r < count; ++r)
            propagateFromRun(runs[r].first, runs[r].second, oldEnds[r].first, oldEnds[r].second);
        // Phase 1 alone guarantees every constraint when it met no pinned point and the hose
        // was valid before: the fast path stops here without measuring.
        if (!hitPin && !h.m_dirtyViolation) return true;
        measured = true;
        const UpdateResult v = h.measureViolation();
        if (v.lengthViolation <= kConvergedLength && v.angleViolation <= kConvergedLength) return true;
        return relax();
    }

    /// Free spans between two pinned points (fixed or grabbed) that lie on the straight line
    /// between them (every free point within 1e-9 of the span's minimum length from the line)
    /// while that line is shorter than the span's minimum length: laid on the circular arc
    /// through both pins on which the span's segments, at their rest lengths, are chords
    /// (the arc's curvature by bisection, 64 steps), bulging towards anyPerpendicular(line),
    /// the fixed perpendicular of the fold-back rule. Returns whether a span was bowed; `before`
    /// receives the state before (only then).
    bool bowFlatCompressedSpans(std::vector<Vec3>& before)
    {
        if (h.m_attachments.empty()) return false; // a grabbed point alone bounds no span
        thread_local std::vector<std::pair<int, int>> pins;
        pins.clear();
        for (const Hose::Attachment& a : h.m_attachments) pins.emplace_back(a.first, a.last);
        if (grabbed >= 0) pins.emplace_back(grabbed, grabbed);
        std::sort(pins.begin(), pins.end());
        bool bowed = false;
        for (size_t r = 1; r < pins.size(); ++r) {
            const int first = pins[r - 1].second, i = pins[r].first;
            if (i <= first + 1) continue;
            const Vec3 start = p[static_cast<size_t>(first)], chord = p[static_cast<size_t>(i)] - start;
            const double minimum =
                h.m_minLengthBefore[static_cast<size_t>(i)] - h.m_minLengthBefore[static_cast<size_t>(first)];
            const double c = chord.norm();
            // A span whose pins coincide has no line to bow from: left to the relaxation.
            if (!(c > 1e-9 * minimum) || !(c < minimum * (1.0 - 1e-9))) continue;
            double longest = 0.0;
            for (int s = first; s < i; ++s) longest = std::max(longest, h.m_restLength[static_cast<size_t>(s)]);
            const Vec3 axis = chord / c;
            bool flat = true;
            for (int k = first + 1; k < i && flat; ++k) {
                const Vec3 d = p[static_cast<size_t>(k)] - start;
                flat = (d - d.dot(axis) * axis).norm() <= 1e-9 * minimum;
            }
            if (!flat) continue;
            const Vec3 up = anyPerpendicular(axis); // the fold-back rule's plane (place())
            // Central angle the span's chords take on a circle of curvature kappa.
            auto angle = [&](double kappa) {
                double total = 0.0;
                for (int s = first; s < i; ++s)
                    total += 2.0 * std::asin(std::min(1.0, 0.5 * kappa * h.m_restLength[static_cast<size_t>(s)]));
                return total;
            };
            // The arc's chord falls from the span's length (kappa → 0) to 0 (a full circle).
            double lo = 0.0, hi = 2.0 / longest;
            for (int step = 0; step < 64; ++step) {
                const double kappa = 0.5 * (lo + hi), phi = angle(kappa);
                const bool longer = phi < 2.0 * std::numbers::pi && 2.0 / kappa * std::sin(0.5 * phi) > c;
                (longer ? lo : hi) = kappa;
            }
            const double kappa = 0.5 * (lo + hi), rho = 1.0 / kappa, phi = angle(kappa);
            const Vec3 centre = start + 0.5 * chord - (rho * std::cos(0.5 * phi)) * up;
            if (!bowed) before = p;
            bowed = true;
            double at = -0.5 * phi;
            for (int k = first + 1; k < i; ++k) {
                at += 2.0 * std::asin(std::min(1.0, 0.5 * kappa * h.m_restLength[static_cast<size_t>(k - 1)]));
                p[static_cast<size_t>(k)] = centre + rho * (std::sin(at) * axis + std::cos(at) * up);
            }
        }
        return bowed;
    }

    /// After an infeasible update: every free span between two pinned points that are farther
    /// apart than the span can stretch is laid on the straight line between them, each segment
    /// stretched in proportion to its maximum length (the least possible worst overstretch).
    void straightenOverlongSpans()
    {
        const int n = h.pointCount();
        int previousPin = -1;
        for (int i = 0; i < n; ++i) {
            if (!pinned(i)) continue;
            if (previousPin >= 0 && i > previousPin + 1) {
                const Vec3 start = p[static_cast<size_t>(previousPin)], end = p[static_cast<size_t>(i)];
                double reach = 0.0;
                for (int s = previousPin; s < i; ++s) reach += h.m_maxLength[static_cast<size_t>(s)];
                if ((end - start).norm() > reach) {
                    double along = 0.0;
                    for (int k = previousPin + 1; k < i; ++k) {
                        along += h.m_maxLength[static_cast<size_t>(k - 1)];
                        p[static_cast<size_t>(k)] = start + (end - start) * (along / reach);
                    }
                }
            }
            previousPin = i;
        }
    }

    Hose& h;
    std::vector<Vec3>& p;
    int grabbed = -1;
    bool newton = true; ///< relax() may finish with newtonFinish()
    bool hitPin = false;
    bool measured = false;
    int movedPoints = 0;
};

double Hose::turnExcess(size_t j, const std::vector<Vec3>& points) const
{
    const Vec3 in = points[j] - points[j - 1], out = points[j + 1] - points[j];
    // Clearly within the limit (cos turn ≥ cos limit, with a margin far above rounding):
    // no need for the angles themselves, the excess is negative.
    const double dot = in.dot(out), lengths = std::sqrt(in.squaredNorm() * out.squaredNorm());
    if (dot >= (m_cosLimit[j] + 1e-9) * lengths && lengths > 0.0) return -1.0;
    const double turn = std::atan2(in.cross(out).norm(), dot);
    return turn - std::atan2(m_sinLimit[j], m_cosLimit[j]);
}

UpdateResult Hose::measureViolation() const
{
    UpdateResult result;
    const size_t n = m_local.size();
    for (size_t s = 0; s + 1 < n; ++s) {
        const double length = (m_local[s + 1] - m_local[s]).norm();
        const double excess = std::max(length - m_maxLength[s], m_minLength[s] - length);
        result.lengthViolation = std::max(result.lengthViolation, excess / m_restLength[s]);
    }
    for (size_t j = 1; j + 1 < n; ++j) {
        result.angleViolation = std::max(result.angleViolation, turnExcess(j, m_local));
    }
    result.status = (result.lengthViolation > 1e-9 || result.angleViolation > 1e-9) ? Status::Infeasible
                                                                                    : Status::Ok;
    return result;
}

bool Hose::blendSide(int from, int side, const Vec3& displacement)
{
    // Warm start between fixed points: spread the displacement of point `from` over the free
    // points towards the nearest fixed point on `side`, fading linearly with rest arc length.
    // A smooth drag then leaves the span nearly relaxed, so the propagation and the relaxation
    // that follow have little left to do. A side without a fixed point is left to phase 1.
    const int n = pointCount();
    int pin = from + side;
    while (pin >= 0 && pin < n && !m_fixed[static_cast<size_t>(pin)]) pin += side;
    if (pin < 0 || pin >= n || pin == from + side) return false;
    double total = 0.0;
    for (int i = from; i != pin; i += side) total += m_restLength[static_cast<size_t>(std::min(i, i + side))];
    double along = 0.0;
    for (int i = pin - side; i != from; i -= side) {
        along += m_restLength[static_cast<size_t>(std::min(i, i + side))];
        m_local[static_cast<size_t>(i)] += displacement * (along / total);
    }
    return true;
}

bool Hose::blendTowardsPins(int index, const Vec3& displacement)
{
    const bool left = blendSide(index, -1, displacement);
    const bool right = blendSide(index, +1, displacement);
    return left || right;
}

int Hose::pinnedSide(int index) const
{
    bool left = false, right = false;
    for (int i = 0; i < pointCount(); ++i)
        if (m_fixed[static_cast<size_t>(i)]) (i < index ? left : right) = true;
    return left == right ? 0 : (left ? -1 : +1);
}

UpdateResult Hose::grab(int index, const Vec3& target)
{
    UpdateResult result;
    if (index < 0 || index >= pointCount() || !target.allFinite() || m_fixed[static_cast<size_t>(index)]) {
        result.status = Status::InvalidInput;
        return result;
    }
    const Vec3 localTarget = target - m_origin;
    const size_t k = static_cast<size_t>(index);
    const Vec3 start = m_local[k];
    const bool mayHitPins = !m_attachments.empty() || m_dirtyViolation;
    const bool heldAtTheEdge = m_edgePoint == index && m_edgeRevision == m_revision;
    // The same target again, nothing changed since this grab stopped at the edge of reach,
    // still held, no colliders (they move without the hose knowing): the same answer, no work.
    if (heldAtTheEdge && m_held == index && m_colliders.empty() && localTarget == m_edgeTarget) {
        result = m_edgeResult;
        result.movedPoints = 0;
        return result;
    }
    bool stoppedAtTheEdge = false;
    if (mayHitPins) m_scratch = m_local;

    bool measured = false;
    bool newtonAllowed = true;
    auto attempt = [&](const Vec3& where, int& moved) {
        Solver solver(*this);
        solver.grabbed = index;
        solver.newton = newtonAllowed;
        const std::pair<int, int> run(index, index);
        const std::pair<Vec3, Vec3> oldEnds(m_local[k], m_local[k]);
        // The blend moves points the propagation may not reach: check the whole hose after it.
        if (mayHitPins) solver.hitPin = blendTowardsPins(index, where - m_local[k]);
        m_local[k] = where;
        const bool converged = solver.solveAfterPlacement(&run, &oldEnds, 1);
        moved = solver.movedPoints;
        measured = solver.measured;
        return converged;
    };

    int moved = 0;
    Status status = Status::Ok;
    if (!attempt(localTarget, moved)) {
        newtonAllowed = false; // the clamps' trials keep the sweeps' own decision
        m_local = m_scratch;
        int movedAtStart = 0;
        if (!attempt(start, movedAtStart)) {
            // The hose was already infeasible before this grab (contradictory attachments):
            // the point moves towards the target only as far as neither the length nor the
            // bend violation grows beyond what it was before the grab: the largest such
            // fraction of the move, by bisection; none (the hose stays as it was) when even
            // relaxing in place would make one of them worse. A grab never makes an
            // infeasible hose worse.
            m_local = m_scratch;
            const UpdateResult before = measureViolation();
            const double lengthBound = before.lengthViolation * (1.0 + 1e-9) + 1e-12;
            const double angleBound = before.angleViolation * (1.0 + 1e-9) + 1e-12;
            auto noWorse = [&](double fraction) {
                m_local = m_scratch;
                attempt(start + fraction * (localTarget - start), moved);
                const UpdateResult v = measureViolation();
                return v.lengthViolation <= lengthBound && v.angleViolation <= angleBound;
            };
            if (!noWorse(1.0)) {
                double good = -1.0, bad = 1.0;
                if (noWorse(0.0)) {
                    good = 0.0;
                    for (int step = 0; step < kBisectionSteps; ++step) {
                        const double mid = 0.5 * (good + bad);
                        (noWorse(mid) ? good : bad) = mid;
                    }
                }
                m_local = m_scratch;
                moved = 0;
                if (good >= 0.0) attempt(start + good * (localTarget - start), moved);
            }
            status = Status::Infeasible;
        } else if (const int side = pinnedSide(index); side != 0) {
            // Reach towards the target as far as the hose allows (closest reachable point).
            m_local = m_scratch;
            Solver solver(*this);
            solver.softClamp(index, localTarget, side);
            moved = pointCount();
            status = Status::Clamped;
        } else {
            // Largest reachable fraction of the move, by bisection (deterministic, bounded).
            // When the last update was this point's grab stopping at the edge of its reach (a
            // target held beyond it), the smallest step the bisection resolves is tried first:
            // a hold then costs one trial, not 16.
            // The state of the last successful trial (the largest reachable fraction found) is
            // kept: the result, bit for bit what a final attempt at that fraction would give.
            double good = 0.0, bad = 1.0;
            const double smallest = std::ldexp(1.0, -kBisectionSteps);
            thread_local std::vector<Vec3> reached;
            int reachedMoved = -1;
            auto trial = [&](double fraction) {
                m_local = m_scratch;
                if (!attempt(start + fraction * (localTarget - start), moved)) return false;
                reached = m_local;
                reachedMoved = moved;
                return true;
            };
            if (heldAtTheEdge) (trial(smallest) ? good : bad) = smallest;
            for (int step = 0; step < kBisectionSteps && bad - good > smallest; ++step) {
                const double mid = 0.5 * (good + bad);
                (trial(mid) ? good : bad) = mid;
            }
            if (reachedMoved >= 0) {
                m_local = reached;
                moved = reachedMoved;
            } else {
                m_local = m_scratch;
                attempt(start, moved);
            }
            status = Status::Clamped;
            stoppedAtTheEdge = true;
        }
    }
    if (measured || status != Status::Ok) {
        const UpdateResult violation = measureViolation();
        result.lengthViolation = violation.lengthViolation;
        result.angleViolation = violation.angleViolation;
        m_dirtyViolation = violation.status != Status::Ok;
        if (status == Status::Ok) status = violation.status;
    }
    result.status = status;
    result.grabError = (m_local[k] - localTarget).norm();
    result.movedPoints = moved;
    m_held = index;
    ++m_revision;
    if (!m_colliders.empty()) applyCollisions(result, index, localTarget); // collision.cpp
    m_edgePoint = stoppedAtTheEdge ? index : -1;
    m_edgeRevision = m_revision;
    m_edgeTarget = localTarget;
    m_edgeResult = result;
    return result;
}

UpdateResult Hose::moveAttachments(const std::vector<int>& ids, const std::vector<Frame>& frames)
{
    UpdateResult result;
    std::vector<Attachment*> targets;
    bool valid = ids.size() == frames.size();
    for (size_t i = 0; valid && i < ids.size(); ++i) {
        auto it = std::find_if(m_attachments.begin(), m_attachments.end(),
                               [&](const Attachment& a) { return a.id == ids[i]; });
        valid = it != m_attachments.end() && isFiniteFrame(frames[i]);
        if (valid) targets.push_back(&*it);
    }
    if (!valid) {
        result.status = Status::InvalidInput;
        return result;
    }
    std::vector<std::pair<int, int>> runs;
    std::vector<std::pair<Vec3, Vec3>> oldEnds;
    bool blended = false;
    for (size_t i = 0; i < targets.size(); ++i) {
        Attachment& a = *targets[i];
        a.frame = frames[i];
        const Vec3 oldFirst = m_local[static_cast<size_t>(a.first)], oldLast = m_local[static_cast<size_t>(a.last)];
        oldEnds.emplace_back(oldFirst, oldLast);
        for (int j = a.first; j <= a.last; ++j)
            m_local[static_cast<size_t>(j)] = a.frame.apply(a.localPoints[static_cast<size_t>(j - a.first)]) - m_origin;
        runs.emplace_back(a.first, a.last);
        // Warm start towards other fixed points (see blendSide).
        blended |= blendSide(a.first, -1, m_local[static_cast<size_t>(a.first)] - oldFirst);
        blended |= blendSide(a.last, +1, m_local[static_cast<size_t>(a.last)] - oldLast);
    }
    Solver solver(*this);
    solver.hitPin = blended; // the blend moved points the propagation may not reach
    const bool converged = solver.solveAfterPlacement(runs.data(), oldEnds.data(), runs.size());
    if (!converged) solver.straightenOverlongSpans();
    if (converged && !solver.measured) {
        result = UpdateResult{}; // phase 1 alone: every constraint holds by construction
    } else {
        result = measureViolation();
        if (!converged && result.status == Status::Ok) result.status = Status::Infeasible;
    }
    m_dirtyViolation = result.status != Status::Ok;
    result.movedPoints = solver.movedPoints;
    ++m_revision;
    if (!m_colliders.empty()) applyCollisions(result, -1, Vec3::Zero()); // collision.cpp
    return result;
}

UpdateResult Hose::settle() { return settleFrom(-1); }

UpdateResult Hose::settleFrom(int held)
{
    Solver solver(*this);
    std::vector<std::pair<int, int>> runs;
    std::vector<std::pair<Vec3, Vec3>> oldEnds;
    for (const Attachment& a : m_attachments) {
        runs.emplace_back(a.first, a.last);
        oldEnds.emplace_back(m_local[static_cast<size_t>(a.first)], m_local[static_cast<size_t>(a.last)]);
    }
    if (held >= 0 && held < pointCount() && !m_fixed[static_cast<size_t>(held)]) {
        solver.grabbed = held;
        runs.emplace_back(held, held);
        oldEnds.emplace_back(m_local[static_cast<size_t>(held)], m_local[static_cast<size_t>(held)]);
    }
    if (runs.empty()) {
        // Nothing fixed: hold point 0 and let the rest follow.
        solver.grabbed = 0;
        runs.emplace_back(0, 0);
        oldEnds.emplace_back(m_local[0], m_local[0]);
    }
    m_dirtyViolation = true; // force the global check
    const bool converged = solver.solveAfterPlacement(runs.data(), oldEnds.data(), runs.size());
    if (!converged) solver.straightenOverlongSpans();
    UpdateResult result = measureViolation();
    if (!converged && result.status == Status::Ok) result.status = Status::Infeasible;
    m_dirtyViolation = result.status != Status::Ok;
    result.movedPoints = solver.movedPoints;
    ++m_revision;
    return result;
}

} // namespace chaintube
