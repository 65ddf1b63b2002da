// The axis solver: grabs and attachment moves without colliders (update.cpp adds the contact
// step, hose_contact.cpp, which calls back only into this solver). The pinned range
// (attachments, the held point) is solved span by span (PinnedSpans: the span solver,
// span_solver.h, with the chain projection, projection.h, where bends must give way), the free
// tails beyond it by the paper's outward propagation (propagation.h).
#include "budget.h"
#include "chaintube/hose.h"
#include "projection.h"
#include "propagation.h"
#include "span_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <tuple>

namespace chaintube {

namespace {
/// The projection's tolerance (relative length, radians): well inside measureViolation()'s 1e-9.
constexpr double kConverged = 1e-10;
/// Newton steps of one projection attempt (the bends giving way: half with soft bends, then
/// this many on the lengths alone).
constexpr int kProjectionSteps = 8;
/// Compliance of the bend rows when the bends must give way to the lengths.
constexpr double kSoftBendCompliance = 0.1;
/// Newton steps of the span solver per span and attempt.
constexpr int kSpanSteps = 12;
/// The same when closing a shape that nearly holds its constraints (Hose::closeSpans): near a
/// solution with saturated joints the steps converge linearly (about a third a step).
constexpr int kCloseSpanSteps = 32;
/// A grab: at most this many steps towards the target, of this many Newton steps each; towards
/// a target that moved since the last grab, ended after this many that brought the point nearer
/// (the rest of the way is covered by the next grabs).
constexpr int kAdvanceSteps = 4;
constexpr int kAdvanceIterations = 6;
constexpr int kMovingAdvanceGains = 1;
/// A target beyond reach is brought this fraction inside the hose's reach.
constexpr double kReachMargin = 1e-6;
/// A grab between fixed points that moves no point by more than this (of the mean rest length)
/// moves nothing: the hose stays as it was, bit for bit. A point held still (the same target
/// each frame) is placed again through the span's kinematics, which moves the points by rounding
/// (up to 4e-11 of a segment measured); the constraints' own tolerance is 1e-9.
constexpr double kNoMove = 1e-9;
/// Under a budget: grabs of the same point towards the same target, each from the shape the one
/// before left, that brought the point less than kStalledGain of its error nearer, in a row,
/// after which the grab is no longer pending: its budgeted steps creep along the edge of what
/// the span reaches or bring the point no nearer at all; it rests where it is (Clamped) unless
/// the target, the shape or the colliders change or the same grab is made again.
constexpr int kStalledGrabs = 3;
constexpr double kStalledGain = 0.01;
/// Clips: the margins a short side is fed to, one attempt each (Hose::slideClips).
constexpr double kClipMargins[] = {0.01, 0.05, 0.15};
// moveAttachments: the fractions of the way the attachments are placed at, one try each; under
// a budget (Hose::setBudget) more and shorter ones, each within a share of it.
constexpr double kFractions[] = {1.0, 0.5};
// Under a budget: the least fraction tried, and the least steps left for another try.
constexpr double kLeastMoveFraction = 1.0 / 64.0;
constexpr int kLeastMoveSteps = 2;
/// Under a budget: attachment-move updates in a row towards the same frames in which only tries of
/// the least fraction advanced and brought the moved attachments less than kStalledMoveGain of
/// their gap nearer their frames, or none did, after which the tries let the bends give way (the
/// lengths alone hold), and updates in a row in which no such try advanced, after which the move
/// rests where it is (no longer pending) or, where the tries before crept, goes back to them.
constexpr int kStalledMoves = 3;
constexpr double kStalledMoveGain = 0.01;
/// The rotation an attachment's points have in `points` (hose-local positions): its frame's
/// rotation turned by the least rotation that takes the direction from its first to its last
/// point where the frame puts it to where it is, then about that direction so that the point
/// farthest off it comes into its plane (only for attachments of points not on one line).
Quat currentRotation(const Hose::Attachment& a, const std::vector<Vec3>& points)
{
    const Quat target = a.frame.rotation;
    if (a.localPoints.size() < 2) return target;
    const Vec3 framed = target * (a.localPoints.back() - a.localPoints.front());
    const Vec3 now = points[static_cast<size_t>(a.last)] - points[static_cast<size_t>(a.first)];
    if (!(framed.norm() > 0.0) || !(now.norm() > 0.0)) return target;
    Quat rotation = (Quat::FromTwoVectors(framed, now) * target).normalized();
    const Vec3 axis = now.normalized();
    double farthest = 1e-9 * now.norm();
    Vec3 from = Vec3::Zero(), to = Vec3::Zero();
    for (size_t j = 1; j + 1 < a.localPoints.size(); ++j) {
        Vec3 placed = rotation * (a.localPoints[j] - a.localPoints.front());
        placed -= placed.dot(axis) * axis;
        if (placed.norm() <= farthest) continue;
        farthest = placed.norm();
        from = placed;
        to = points[static_cast<size_t>(a.first) + j] - points[static_cast<size_t>(a.first)];
        to -= to.dot(axis) * axis;
    }
    if (from.squaredNorm() > 0.0 && to.squaredNorm() > 0.0)
        rotation =
            (Quat(Eigen::AngleAxisd(std::atan2(from.cross(to).dot(axis), from.dot(to)), axis)) *
             rotation)
                .normalized();
    return rotation;
}

using detail::anyPerpendicular;

} // namespace

double Hose::turnExcess(size_t j, const std::vector<Vec3>& points) const
{
    if (m_cosLimit[j] <= -1.0) return -1.0; // no limit (π): no turn exceeds it
    const Vec3 in = points[j] - points[j - 1], out = points[j + 1] - points[j];
    // Clearly within the limit (cos turn ≥ cos limit, with a margin far above rounding):
    // no need for the angles themselves, the excess is negative.
    const double dot = in.dot(out), lengths = std::sqrt(in.squaredNorm() * out.squaredNorm());
    if (dot >= (m_cosLimit[j] + 1e-9) * lengths && lengths > 0.0) return -1.0;
    // turn − limit from the difference's sine and cosine (both scaled by |in| |out|): at a
    // joint held on its limit (within half a degree, |tan| ≤ 1/128) by the series of atan up
    // to x⁷, whose next term is below 2e-18 of the result; atan2 farther off.
    const double sinTurn = in.cross(out).norm();
    const double s = sinTurn * m_cosLimit[j] - dot * m_sinLimit[j];
    const double c = dot * m_cosLimit[j] + sinTurn * m_sinLimit[j];
    if (c > 0.0 && std::abs(s) <= c * (1.0 / 128.0)) {
        const double x = s / c, x2 = x * x;
        return x * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0))));
    }
    return std::atan2(s, c);
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
    result.status = (result.lengthViolation > 1e-9 || result.angleViolation > 1e-9)
                        ? Status::Infeasible
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
    while (pin >= 0 && pin < n && !m_fixed[static_cast<size_t>(pin)])
        pin += side;
    if (pin < 0 || pin >= n || pin == from + side) return false;
    double total = 0.0;
    for (int i = from; i != pin; i += side)
        total += m_restLength[static_cast<size_t>(std::min(i, i + side))];
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

namespace {

/// The range from the first to the last point of the hose's attachments, widened to `held`
/// (−1: none); first > last when there is nothing pinned.
std::pair<int, int> pinnedRange(const std::vector<Hose::Attachment>& attachments, int held)
{
    int first = held >= 0 ? held : std::numeric_limits<int>::max();
    int last = held >= 0 ? held : -1;
    for (const Hose::Attachment& a : attachments) {
        first = std::min(first, a.first);
        last = std::max(last, a.last);
    }
    return {first, last};
}

/// The closest point to `target` within both balls (centre, radius); the balls must overlap.
/// `b` may be absent (radius < 0): then the closest point within the first ball.
Vec3 closestInTwoBalls(const Vec3& target, const Vec3& a, double ra, const Vec3& b, double rb)
{
    auto inA = [&](const Vec3& q) { return (q - a).norm() <= ra * (1.0 + 1e-12); };
    auto inB = [&](const Vec3& q) { return rb < 0.0 || (q - b).norm() <= rb * (1.0 + 1e-12); };
    auto ontoSphere = [](const Vec3& q, const Vec3& centre, double radius) {
        const Vec3 d = q - centre;
        const double length = d.norm();
        return length > 0.0 ? Vec3(centre + d * (radius / length))
                            : Vec3(centre + radius * Vec3::UnitX());
    };
    if (inA(target) && inB(target)) return target;
    if (!inA(target)) {
        const Vec3 q = ontoSphere(target, a, ra);
        if (inB(q)) return q;
    }
    if (rb >= 0.0 && !inB(target)) {
        const Vec3 q = ontoSphere(target, b, rb);
        if (inA(q)) return q;
    }
    if (rb < 0.0) return ontoSphere(target, a, ra);
    // On the circle where the two spheres meet.
    const Vec3 axis = b - a;
    const double d = axis.norm();
    if (!(d > 0.0)) return ontoSphere(target, a, std::min(ra, rb));
    const Vec3 u = axis / d;
    const double along = std::clamp((d * d + ra * ra - rb * rb) / (2.0 * d), -ra, ra);
    const Vec3 centre = a + along * u;
    const double radius = std::sqrt(std::max(0.0, ra * ra - along * along));
    Vec3 across = (target - centre) - (target - centre).dot(u) * u;
    if (!(across.norm() > 1e-300)) across = anyPerpendicular(u);
    return centre + radius * across.normalized();
}

} // namespace

/// The pinned spans of one update: sweeps (robust from any start) hand over to the chain
/// projection (quadratic once close), both bounded, over the range from the first to the
/// last pinned point; the free tails beyond it by the paper's pass.
class PinnedSpans
{
public:
    PinnedSpans(Hose& hose, int first, int last, int heldPoint)
        : h(hose), projection(hose), lo(first), hi(last), held(heldPoint)
    {
        projection.setRange(lo, hi);
    }

    /// Solves every span between consecutive anchors of the range (pinned points of runs of
    /// two or more points, and the range's ends) with the span solver (span_solver.h), from the
    /// current positions, which must hold the pinned points where they must be. Single pinned
    /// points inside a span (the held point, one-point attachments) are goals the span passes
    /// through: hard, except the held point when `heldSoft` (then as near as the span allows).
    /// A span ending at the held point (a grab beyond the last attachment) ends there, free
    /// when `heldSoft`. Returns whether every span is valid; `heldMet` whether the held point is
    /// where it was put.
    bool solveSpans(int& iterations, bool heldSoft, bool& heldMet, bool writeAnyway = false,
                    const Vec3* heldTarget = nullptr)
    {
        const int n = h.pointCount();
        auto pinned = [&](int i) { return h.m_fixed[static_cast<size_t>(i)] != 0 || i == held; };
        auto inRun = [&](int i) {
            return h.m_fixed[static_cast<size_t>(i)] &&
                   ((i > 0 && h.m_fixed[static_cast<size_t>(i - 1)] && sameRun(i - 1, i)) ||
                    (i + 1 < n && h.m_fixed[static_cast<size_t>(i + 1)] && sameRun(i, i + 1)));
        };
        bool valid = true;
        heldMet = true;
        int anchor = lo;
        std::vector<detail::SpanGoal> goals;
        for (int i = lo + 1; i <= hi; ++i) {
            if (!pinned(i)) continue;
            const bool isAnchor = i == hi || inRun(i);
            if (!isAnchor) {
                goals.push_back({i, h.m_local[static_cast<size_t>(i)], !(heldSoft && i == held)});
                continue;
            }
            if (i > anchor + 1 || (i == anchor + 1 && (i == held || anchor == held))) {
                // The span anchor … i, rooted at a fixed end: at the held point only if the
                // other end is the held point at the range's end.
                const bool reverse = anchor == held;
                const int root = reverse ? i : anchor, end = reverse ? anchor : i;
                const int dir = end > root ? 1 : -1;
                Vec3 rootDirection, endDirection;
                const int beforeRoot = root - dir, afterEnd = end + dir;
                const bool haveRoot = beforeRoot >= 0 && beforeRoot < n && pinned(beforeRoot) &&
                                      sameRun(beforeRoot, root);
                const bool haveEnd =
                    afterEnd >= 0 && afterEnd < n && pinned(afterEnd) && sameRun(end, afterEnd);
                if (haveRoot)
                    rootDirection = (h.m_local[static_cast<size_t>(root)] -
                                     h.m_local[static_cast<size_t>(beforeRoot)])
                                        .normalized();
                if (haveEnd)
                    endDirection = (h.m_local[static_cast<size_t>(afterEnd)] -
                                    h.m_local[static_cast<size_t>(end)])
                                       .normalized();
                const bool endIsHeld = end == held;
                const bool endFixed = !(endIsHeld && heldSoft);
                const Vec3 endTarget = h.m_local[static_cast<size_t>(end)];
                detail::SpanSolver solver(h);
                int moving = -2; // the held point's goal (−1: the span's end), −2: not in this span
                for (size_t g = 0; g < goals.size(); ++g)
                    if (goals[g].point == held) moving = static_cast<int>(g);
                if (endIsHeld) moving = -1;
                // A span ending at the held point: the end is free (so the span is valid after
                // every step) and goes as near its target as the budget brings it.
                if (heldTarget && moving == -1) {
                    const detail::SpanSolver::Outcome out = solver.solve(
                        root, end, false, *heldTarget, goals, haveRoot ? &rootDirection : nullptr,
                        nullptr, spanSteps, kConverged);
                    iterations += out.iterations;
                    heldMet = heldMet && out.goalsMet;
                    if (out.goalsMet) h.m_local[static_cast<size_t>(end)] = *heldTarget;
                    goals.clear();
                    anchor = i;
                    continue;
                }
                const detail::SpanSolver::Outcome out =
                    heldTarget && moving > -2
                        ? solver.advance(root, end, endTarget, goals, moving, *heldTarget,
                                         haveRoot ? &rootDirection : nullptr,
                                         haveEnd ? &endDirection : nullptr, kAdvanceSteps,
                                         kMovingAdvanceGains, kAdvanceIterations, kConverged,
                                         requested)
                        : solver.solve(root, end, endFixed, endTarget, goals,
                                       haveRoot ? &rootDirection : nullptr,
                                       haveEnd ? &endDirection : nullptr, spanSteps, kConverged,
                                       writeAnyway);
                iterations += out.iterations;
                valid = valid && out.valid;
                if (!out.goalsMet) {
                    for (const detail::SpanGoal& g : goals)
                        heldMet = heldMet && g.point != held;
                    if (endIsHeld) heldMet = false;
                }
            }
            goals.clear();
            anchor = i;
        }
        return valid;
    }

    /// Whether points a and b (adjacent, both fixed) belong to the same attachment.
    bool sameRun(int a, int b) const
    {
        for (const Hose::Attachment& run : h.m_attachments)
            if (a >= run.first && a <= run.last) return b >= run.first && b <= run.last;
        return false;
    }

    /// Pinned points stay, every constraint holds: solveSpans() with the held point hard.
    bool hard(int& iterations)
    {
        bool met = false;
        return solveSpans(iterations, false, met) && met;
    }

    /// Every span from the current positions: a straight span shorter than its hose bowed
    /// first; if no valid shape is found, a start with bends beyond their limits is repaired
    /// (repairBends), else the bends give way and the span solver is tried once more from that
    /// shape (its lengths hold and its ends are met: a start near a valid shape where the warm
    /// start was not); where the projection leaves lengths outside their bands, the span solver
    /// closes from there within the turns it left (hardWithinTurns). Returns whether the
    /// lengths hold (the bends may not).
    bool solveBowingOrKinking(int& iterations, bool closeWithinTurns = true)
    {
        Solver bow(h);
        bow.grabbed = held;
        std::vector<Vec3> flat;
        bool solved = false;
        if (bow.bowFlatCompressedSpans(flat)) {
            solved = hard(iterations);
            if (!solved) h.m_local = std::move(flat);
        }
        if (!solved) solved = hard(iterations);
        if (solved) return true;
        // A start with a joint beyond its limit (a kink left by an earlier update): the chain
        // projection with hard bends onto the limits, else onto limits that allow half of each
        // joint's excess (the span solver's clamp at its start turns the rest of the chain with
        // each joint it clamps, so it rarely closes from a kink): a kink whose cause is gone
        // straightens over the next updates.
        if (repairBends(iterations, 0.0) || repairBends(iterations, 0.5)) return true;
        if (bendsGiveWay(iterations)) {
            std::vector<Vec3> kinked = h.m_local;
            if (!hard(iterations)) h.m_local = std::move(kinked);
            return true;
        }
        // The projection did not bring the lengths into their bands: the span solver closes
        // the spans from where it left them, each joint allowed the turn it has there (the
        // lengths hold by construction, and the ends are met wherever they are within reach;
        // not tried for ends brought into reach, `closeWithinTurns` false, where the span is
        // nearly taut and it does not close).
        return closeWithinTurns && hardWithinTurns(iterations, 1.0);
    }

    /// hard() within limits widened as withinWidenedLimits() widens them: with `share` 1 the
    /// bends give way no more than they do in the current shape. False at once when no joint
    /// exceeds its limit (hard() then has nothing more to allow).
    bool hardWithinTurns(int& iterations, double share)
    {
        return withinWidenedLimits(share, [&] { return hard(iterations); });
    }

    /// The chain projection with hard bends and lengths from the current shape, each joint
    /// whose turn exceeds its limit allowed `share` of that excess (withinWidenedLimits); the
    /// shape is kept only when it converges. False at once when no joint exceeds its limit.
    bool repairBends(int& iterations, double share)
    {
        const std::vector<Vec3> start = h.m_local;
        const bool converged = withinWidenedLimits(share, [&] {
            projection.useMassesFromRestLengths(held);
            projection.setBendCompliance(0.0);
            projection.setBends(true);
            const detail::ProjectionOutcome out = projection.run(kProjectionSteps, kConverged);
            iterations += out.iterations;
            return out.converged;
        });
        if (!converged) h.m_local = start;
        return converged;
    }

    /// Marks in `tight` (per segment) the segments on either side of each joint of the range
    /// that bends tighter than the material's minimum bend radius when its radius is taken from
    /// its segments' current lengths (as measure() takes it): a joint on its limit (derived
    /// from the rest lengths) between compressed segments. Returns whether there is one.
    bool bendsBelowMinimumRadius()
    {
        const BendLimit& limit = h.m_spec.material.bendLimit;
        if (limit.kind != BendLimit::Kind::MinBendRadius || !(limit.value > 0.0)) return false;
        const int from = std::max(lo, 1), to = std::min(hi, h.pointCount() - 2);
        tight.assign(h.m_restLength.size(), 0);
        bool any = false;
        for (int j = from; j <= to; ++j) {
            const size_t k = static_cast<size_t>(j);
            // A single free point between two pinned ones: its lengths alone place it.
            if (h.m_fixed[k - 1] && h.m_fixed[k + 1]) continue;
            const Vec3 in = h.m_local[k] - h.m_local[k - 1], out = h.m_local[k + 1] - h.m_local[k];
            const double turn = std::atan2(in.cross(out).norm(), in.dot(out));
            if (bendRadiusOfTurn(0.5 * (in.norm() + out.norm()), turn) <
                limit.value * (1.0 - 1e-9)) {
                tight[k - 1] = tight[k] = 1;
                any = true;
            }
        }
        return any;
    }

    /// A valid shape with a bend tighter than the minimum radius (bendsBelowMinimumRadius):
    /// the spans solved again (hard()) with the band of each segment beside such a bend
    /// narrowed to its rest length, else to half of its way there (its length may only come
    /// nearer its rest length), the shape kept only when that is valid: the segments return to
    /// their rest lengths over the next updates. Returns whether the shape changed.
    bool relaxCompressedBends(int& iterations)
    {
        if (!bendsBelowMinimumRadius()) return false;
        const std::vector<Vec3> start = h.m_local;
        for (const double share : {0.0, 0.5}) {
            bands.clear();
            for (int seg = lo; seg < hi; ++seg) {
                const size_t k = static_cast<size_t>(seg);
                if (!tight[k] || (h.m_fixed[k] && h.m_fixed[k + 1])) continue;
                bands.push_back({k, h.m_minLength[k], h.m_maxLength[k]});
                const double l = (start[k + 1] - start[k]).norm(), rest = h.m_restLength[k];
                h.m_minLength[k] =
                    std::max(h.m_minLength[k], rest - share * std::max(0.0, rest - l));
                h.m_maxLength[k] =
                    std::min(h.m_maxLength[k], rest + share * std::max(0.0, l - rest));
            }
            const bool relaxed = hard(iterations);
            for (const auto& [k, low, high] : bands) {
                h.m_minLength[k] = low;
                h.m_maxLength[k] = high;
            }
            if (relaxed) return true;
            h.m_local = start;
        }
        return false;
    }

    /// Runs `solve` with each joint of the range whose turn in the current shape exceeds its
    /// limit allowed `share` of that excess beyond the limit (share 1: its turn and 1e-9 rad,
    /// so the shape starts inside every limit); the hose's own limits hold again on return,
    /// bit for bit. Returns false without running it when no joint
    /// exceeds its limit, else what `solve` returns.
    template <class Solve> bool withinWidenedLimits(double share, Solve&& solve)
    {
        const int from = std::max(lo, 1), to = std::min(hi, h.pointCount() - 2);
        widened.clear();
        for (int j = from; j <= to; ++j) {
            const size_t k = static_cast<size_t>(j);
            const double excess = h.turnExcess(k, h.m_local);
            if (excess > 0.0)
                widened.push_back(
                    {k, std::min(std::numbers::pi, h.m_limitAngle[k] + share * excess +
                                                       (share >= 1.0 ? 1e-9 : 0.0))});
        }
        if (widened.empty()) return false;
        // Each joint's six limit values as they were, restored exactly.
        saved.clear();
        for (const auto& [k, limit] : widened) {
            saved.push_back({h.m_cosLimit[k], h.m_sinLimit[k], h.m_limitAngle[k],
                             h.m_cosHalfLimit[k], h.m_sinHalfLimit[k], h.m_chordLimit2[k]});
            h.m_cosLimit[k] = std::cos(limit);
            h.m_sinLimit[k] = std::sin(limit);
            h.m_limitAngle[k] = limit;
            h.m_cosHalfLimit[k] = std::cos(0.5 * limit);
            h.m_sinHalfLimit[k] = std::sin(0.5 * limit);
            h.m_chordLimit2[k] =
                4.0 * h.m_sinHalfLimit[k] * h.m_sinHalfLimit[k] + 2e-12 * limit + 1e-24;
        }
        const bool solved = solve();
        for (size_t i = 0; i < widened.size(); ++i) {
            const size_t k = widened[i].first;
            const std::array<double, 6>& v = saved[i];
            h.m_cosLimit[k] = v[0], h.m_sinLimit[k] = v[1], h.m_limitAngle[k] = v[2];
            h.m_cosHalfLimit[k] = v[3], h.m_sinHalfLimit[k] = v[4], h.m_chordLimit2[k] = v[5];
        }
        return solved;
    }

    /// The bends give way to the lengths (pinned points stay): soft bend rows, then the
    /// lengths alone to their tolerance. For ends whose positions and tangents leave no shape
    /// within the bend limits.
    /// `split`: under a budget the soft bend rows take half of what is left, the lengths the rest.
    bool bendsGiveWay(int& iterations, bool split = false)
    {
        projection.useMassesFromRestLengths(held);
        projection.setBendCompliance(kSoftBendCompliance);
        projection.setBends(true);
        detail::ProjectionOutcome out;
        {
            BudgetShare soft(h, split ? BudgetShare::half(h, false) : h.m_budgetLeft);
            out = projection.run(kProjectionSteps / 2, kConverged);
        }
        iterations += out.iterations;
        projection.setBendCompliance(0.0);
        if (out.converged) return true;
        projection.setBends(false);
        out = projection.run(kProjectionSteps, kConverged);
        iterations += out.iterations;
        projection.setBends(true);
        return out.converged;
    }

    Hose& h;
    detail::ChainProjection projection;
    int lo, hi, held;
    int spanSteps = kSpanSteps;      ///< Newton steps of the span solver per span
    const Vec3* requested = nullptr; ///< a grab's target when its goal is clamped into reach
    std::vector<std::pair<size_t, double>> widened; ///< withinWidenedLimits(): joints, limits
    std::vector<std::array<double, 6>> saved;       ///< withinWidenedLimits(): their own limits
    std::vector<std::tuple<size_t, double, double>> bands; ///< relaxCompressedBends(): own bands
    std::vector<unsigned char> tight; ///< bendsBelowMinimumRadius(): per segment
};

namespace {

/// Sum of the maximum segment lengths between points `from` and `to` (either order).
double reachBetween(const Hose& hose, int from, int to)
{
    double reach = 0.0;
    for (int s = std::min(from, to); s < std::max(from, to); ++s)
        reach += hose.maxLength(s);
    return reach;
}

/// Whether no point of `now` is farther than `most` from its place in `before`.
bool movedWithin(const std::vector<Vec3>& now, const std::vector<Vec3>& before, double most)
{
    const double most2 = most * most;
    for (size_t i = 0; i < now.size(); ++i)
        if ((now[i] - before[i]).squaredNorm() > most2) return false;
    return true;
}

/// Nearest fixed point from `index` going `side` (±1), or −1.
int nearestFixed(const Hose& hose, int index, int side)
{
    for (int i = index + side; i >= 0 && i < hose.pointCount(); i += side)
        if (hose.isFixed(i)) return i;
    return -1;
}

} // namespace

bool Hose::grabAccepts(int index, const Vec3& target) const
{
    return index >= 0 && index < pointCount() && target.allFinite() &&
           !m_fixed[static_cast<size_t>(index)];
}

Hose::GrabSolve Hose::solveGrab(int index, const Vec3& target)
{
    GrabSolve solve;
    UpdateResult& result = solve.result;
    m_updatedSinceStep = true;
    const Vec3 localTarget = target - m_origin;
    const size_t k = static_cast<size_t>(index);
    solve.revisionBefore = m_revision;
    // The same target again, nothing changed since a grab of this point moved nothing (its point
    // was on that target, or got no nearer to it) and did not run out of budget, still held, no
    // colliders (they move without the hose knowing): no work.
    const bool sameAsLastMiss =
        m_edgePoint == index && m_edgeRevision == m_revision && localTarget == m_edgeTarget;
    if (sameAsLastMiss && !m_edgeResult.pending && m_held == index && m_colliders.empty()) {
        result = m_edgeResult;
        result.movedPoints = 0;
        result.iterations = 0;
        solve.answered = true;
        return solve;
    }
    const bool wasInvalid = m_dirtyViolation;
    const UpdateResult before = wasInvalid ? measureViolation() : UpdateResult{};
    Status status = Status::Ok;
    int moved = 0;
    // Clips: the hose first slides through them where a side needs length to reach the target
    // (slideClips), the spans made valid again around the clips' new places; the grab then
    // goes on from there. A slide that leaves no valid shape is undone.
    // Under a budget the slides get half of it and the grab goes on with the rest; slides that
    // came to nothing for this point and target are not tried again from the same shape (they
    // would spend the same steps on the same outcome in every update while the grab waits).
    std::vector<Vec3> beforeSlide;
    const bool clips = std::any_of(m_attachments.begin(), m_attachments.end(),
                                   [](const Attachment& a) { return a.isClip(); });
    bool slidesMissed = false;
    if (clips && !wasInvalid && !(sameAsLastMiss && m_edgeSlidesMissed)) {
        const std::vector<Attachment> attachmentsBefore = m_attachments;
        const std::vector<unsigned char> fixedBefore = m_fixed;
        beforeSlide = m_local;
        BudgetShare slideShare(*this, BudgetShare::half(*this, false));
        for (const double margin : kClipMargins) {
            if (slideClips(index, &localTarget, margin).empty() ||
                closeSpans(index, beforeSlide, result.iterations))
                break;
            m_attachments = attachmentsBefore;
            m_fixed = fixedBefore;
            m_local = beforeSlide;
        }
        slidesMissed = m_local == beforeSlide;
    }
    m_scratch = m_local;
    const Vec3 start = m_local[k];
    Vec3 goal = localTarget; // where the point goes: the target, or the nearest point in reach
    if (m_attachments.empty()) {
        // Nothing fixed: the paper's propagation alone.
        Solver solver(*this);
        solver.grabbed = index;
        m_local[k] = localTarget;
        solver.propagateFromRun(index, index, start, start);
        moved = solver.movedPoints;
    } else {
        // Beyond reach: the point goes to the reachable position closest to the target (within
        // both pins' reach, less a margin that keeps the span off the singular taut state).
        const int left = nearestFixed(*this, index, -1), right = nearestFixed(*this, index, +1);
        const double margin = 1.0 - kReachMargin;
        if (left >= 0 && right >= 0)
            goal = closestInTwoBalls(localTarget, m_local[static_cast<size_t>(left)],
                                     margin * reachBetween(*this, left, index),
                                     m_local[static_cast<size_t>(right)],
                                     margin * reachBetween(*this, index, right));
        // (Fixed on one side only, the free end goes as near the target as it can by itself.)
        if (goal != localTarget) status = Status::Clamped;
        const auto [lo, hi] = pinnedRange(m_attachments, index);
        PinnedSpans spans(*this, lo, hi, index);
        if (goal != localTarget) spans.requested = &localTarget;
        // From the current, valid shape the point goes towards its goal in valid steps: exactly
        // there, else as near as the budget brings it (the rest on the next updates). A shape
        // that was not valid is solved with the point at its goal, else as near as it gets.
        bool met = false;
        bool solved = false;
        // A straight span the move would push shorter than it can be: bowed first (hose.h),
        // then solved with the point at its goal.
        m_local[k] = goal;
        std::vector<Vec3> flat;
        Solver bow(*this);
        bow.grabbed = index;
        if (!wasInvalid && bow.bowFlatCompressedSpans(flat)) {
            solved = spans.solveSpans(result.iterations, false, met) && met;
            if (!solved) m_local = m_scratch;
        } else {
            m_local[k] = start;
        }
        if (solved) {
        } else if (!wasInvalid) {
            solved = spans.solveSpans(result.iterations, false, met, false, &goal);
            if (!met) status = Status::Clamped;
        } else {
            m_local[k] = goal;
            solved = spans.solveSpans(result.iterations, false, met) && met;
        }
        if (!solved) {
            m_local = m_scratch;
            m_local[k] = goal;
            solved = spans.solveSpans(result.iterations, true, met);
            status = Status::Clamped;
        }
        if (solved) {
            Solver tails(*this);
            tails.grabbed = index;
            tails.sweepTails(lo, hi, m_scratch, wasInvalid);
        } else {
            m_local = m_scratch;
            status = Status::Clamped;
        }
        const std::vector<Vec3>& unmoved = beforeSlide.empty() ? m_scratch : beforeSlide;
        for (size_t i = 0; i < m_local.size(); ++i)
            moved += m_local[i] != unmoved[i];
        // Moved by no more than kNoMove (no clip slid, a valid shape before): nothing moved, so a
        // hose held still comes to rest and stays there (step()).
        if (moved > 0 && beforeSlide.empty() && !wasInvalid &&
            movedWithin(m_local, m_scratch, kNoMove * restLengthTotal() / segmentCount())) {
            m_local = m_scratch;
            moved = 0;
        }
    }
    if (wasInvalid) {
        // A grab never makes a hose that already violated its constraints worse.
        const UpdateResult after = measureViolation();
        if (after.lengthViolation > before.lengthViolation * (1.0 + 1e-9) + 1e-12 ||
            after.angleViolation > before.angleViolation * (1.0 + 1e-9) + 1e-12) {
            m_local = m_scratch;
            moved = 0;
            result.lengthViolation = before.lengthViolation;
            result.angleViolation = before.angleViolation;
            status = Status::Infeasible;
        } else {
            result.lengthViolation = after.lengthViolation;
            result.angleViolation = after.angleViolation;
            if (after.status != Status::Ok) status = Status::Infeasible;
            m_dirtyViolation = after.status != Status::Ok;
        }
    }
    result.status = status;
    result.grabError = (m_local[k] - localTarget).norm();
    result.movedPoints = moved;
    m_held = index;
    if (moved > 0 || m_attachments.empty()) ++m_revision;
    solve.goal = goal;
    solve.moved = moved;
    solve.slidesMissed = slidesMissed;
    return solve;
}

UpdateResult Hose::finishGrab(int index, const Vec3& target, const GrabSolve& solve, bool budgetCut)
{
    UpdateResult result = solve.result;
    const Vec3 localTarget = target - m_origin;
    const size_t k = static_cast<size_t>(index);
    const Vec3& goal = solve.goal;
    const std::uint64_t revisionBefore = solve.revisionBefore;
    // Cut short by the budget: step() goes on towards the same target, unless kStalledGrabs
    // grabs in a row towards it gained little (kStalledGain).
    const double remaining = (m_local[k] - goal).norm();
    const bool sameGrab = m_grabStall.point == index && m_grabStall.revision == revisionBefore &&
                          m_grabStall.target == localTarget;
    const bool gainedLittle =
        sameGrab && !(result.grabError < m_grabStall.error * (1.0 - kStalledGain));
    const int stalled = gainedLittle ? m_grabStall.count + 1 : 0;
    m_grabStall = {index, m_revision, localTarget, result.grabError, stalled};
    result.pending = budgetCut && remaining > 0.0 && stalled < kStalledGrabs;
    result.remaining = result.pending ? remaining : 0.0;
    m_pendingGrab = result.pending;
    m_pendingGrabRemaining = result.remaining;
    m_pendingGrabTarget = target;
    // Remember a grab that moved nothing (on its target, or at the edge of its reach and no
    // nearer): the same target again, from the same shape, is answered at once, unless it ran
    // out of budget (then the same target again goes on, without the slides that missed).
    m_edgePoint = solve.moved == 0 ? index : -1;
    m_edgeRevision = m_revision;
    m_edgeTarget = localTarget;
    m_edgeResult = result;
    m_edgeSlidesMissed = solve.slidesMissed;
    return result;
}

UpdateResult Hose::grabWithoutContacts(int index, const Vec3& target)
{
    if (!grabAccepts(index, target)) {
        UpdateResult result;
        result.status = Status::InvalidInput;
        return result;
    }
    BudgetScope scope(*this);
    const GrabSolve solve = solveGrab(index, target);
    return solve.answered ? solve.result : finishGrab(index, target, solve, scope.cut());
}

UpdateResult Hose::solveAttachmentMove(const std::vector<int>& ids,
                                       const std::vector<Frame>& frames)
{
    UpdateResult result;
    std::vector<Attachment*> targets;
    bool valid = ids.size() == frames.size();
    for (size_t i = 0; valid && i < ids.size(); ++i) {
        Attachment* a = attachmentWithId(ids[i]);
        valid = a && isFiniteFrame(frames[i]);
        if (valid) targets.push_back(a);
    }
    if (!valid) {
        result.status = Status::InvalidInput;
        return result;
    }
    m_scratch = m_local;
    // Clips: the hose first slides through them where a side needs length to reach its
    // attachments' new places (slideClips; a clip moved along its axis from where the hose
    // stays); the clips that slid are placed with the moved ones.
    // A slide whose shape leaves a bend beyond its limit (a side whose ends' directions need
    // more than its straight-line demand) is tried again with wider margins (kClipMargins).
    // Undone when no valid shape is found.
    const bool clips = std::any_of(m_attachments.begin(), m_attachments.end(),
                                   [](const Attachment& a) { return a.isClip(); });
    // How far each moved clip's centre moves along its axis (clip id, metres).
    bool framesChanged = false;
    std::vector<std::pair<int, double>> axialShifts;
    for (size_t i = 0; i < targets.size(); ++i) {
        const Attachment& a = *targets[i];
        if (a.isClip())
            axialShifts.emplace_back(a.id,
                                     (frames[i].apply(a.clipCentre) - a.frame.apply(a.clipCentre))
                                         .dot((a.frame.rotation * a.clipAxis).normalized()));
        framesChanged = framesChanged || targets[i]->frame.translation != frames[i].translation ||
                        targets[i]->frame.rotation.coeffs() != frames[i].rotation.coeffs();
        targets[i]->frame = frames[i];
    }
    // Towards other frames, a stall (kStalledMoves) counts anew.
    if (framesChanged) m_moveStall = MoveStall{};
    // How far the moved attachments are from their frames before the update (kStalledMoves).
    double gapBefore = 0.0;
    for (const Attachment* a : targets)
        gapBefore = std::max(gapBefore, attachmentGap(a->id));
    const std::vector<Attachment> attachmentsBefore =
        clips ? m_attachments : std::vector<Attachment>();
    const std::vector<unsigned char> fixedBefore = clips ? m_fixed : std::vector<unsigned char>();
    const std::vector<Attachment*> moved = targets;
    bool partialMove = false;      // under a budget: the attachments moved part of the way
    bool beyondReach = false;      // some frame is beyond the hose's reach
    bool budgetedProgress = false; // under a budget: a try advanced
    bool budgetedLong = false;     // under a budget: a try longer than the least advanced
    bool leastFailed = false;      // under a budget: a try of the least fraction found nothing
    const auto restoreClips = [&] {
        for (size_t i = 0; i < m_attachments.size(); ++i)
            if (m_attachments[i].isClip()) m_attachments[i] = attachmentsBefore[i];
        m_fixed = fixedBefore;
    };
    const bool wasInvalid = m_dirtyViolation;
    std::vector<Vec3> slidCopy;
    UpdateResult violation;
    // A clip moved along its axis: when no shape is found from its slide as it was, the margins
    // again from where that move takes the slide (the hose staying where it is).
    const int margins = static_cast<int>(std::size(kClipMargins));
    const bool clipMoved =
        std::any_of(axialShifts.begin(), axialShifts.end(), [&](const auto& shift) {
            return std::abs(shift.second) > 1e-12 * m_restLength.front();
        });
    const int attempts = clips ? (clipMoved ? 2 : 1) * margins : 1;
    for (int attempt = 0; attempt < attempts; ++attempt) {
        if (attempt > 0) {
            restoreClips();
            targets = moved;
        }
        m_local = m_scratch;
        if (clips)
            for (const int id : slideClips(-1, nullptr, kClipMargins[attempt % margins],
                                           attempt >= margins ? &axialShifts : nullptr)) {
                Attachment* slid = attachmentWithId(id);
                if (std::find(targets.begin(), targets.end(), slid) == targets.end())
                    targets.push_back(slid);
            }
        // Clips first: the moved attachments' reach is measured from where the clips now hold.
        std::stable_partition(targets.begin(), targets.end(),
                              [](const Attachment* a) { return a->isClip(); });
        // m_scratch with the slid clips' points moved.
        if (clips) slidCopy = m_local;
        // Where the attachments are placed from: the shape before the move, under a budget the
        // last valid shape a try of this update reached.
        std::vector<Vec3> base = clips ? slidCopy : m_scratch;
        m_local = base;
        // Where each moved attachment's points go: at its frame, or, when that is beyond the
        // hose's reach from its neighbouring fixed points, moved straight towards where the
        // hose reaches (a gap, Hose::attachmentGap). Part of the way (fraction < 1): its first
        // point that fraction of the way from where it is; under a budget its rotation also
        // turned that fraction of the way from the one its points have (currentRotation).
        bool broughtIntoReach = false; // place(): some frame is beyond reach
        const bool bounded = m_budgetLeft >= 0;
        auto place = [&](double fraction) {
            m_local = base;
            broughtIntoReach = false;
            const double margin = 1.0 - kReachMargin;
            for (const Attachment* a : targets) {
                const size_t first = static_cast<size_t>(a->first),
                             last = static_cast<size_t>(a->last);
                const Vec3 oldFirst = base[first], oldLast = base[last];
                Frame frame = a->frame;
                if (bounded && fraction < 1.0)
                    frame.rotation =
                        currentRotation(*a, base).slerp(fraction, a->frame.rotation).normalized();
                // The first point's place at `fraction` of the way, before the reach.
                const Vec3 wanted = oldFirst + fraction * (a->frame.apply(a->localPoints.front()) -
                                                           m_origin - oldFirst);
                const Vec3 lastOffset =
                    frame.apply(a->localPoints.back()) - frame.apply(a->localPoints.front());
                Vec3 firstAt = wanted;
                const int left = nearestFixed(*this, a->first, -1),
                          right = nearestFixed(*this, a->last, +1);
                if (left >= 0 && right >= 0)
                    firstAt = closestInTwoBalls(firstAt, m_local[static_cast<size_t>(left)],
                                                margin * reachBetween(*this, left, a->first),
                                                m_local[static_cast<size_t>(right)] - lastOffset,
                                                margin * reachBetween(*this, a->last, right));
                else if (left >= 0)
                    firstAt = closestInTwoBalls(firstAt, m_local[static_cast<size_t>(left)],
                                                margin * reachBetween(*this, left, a->first),
                                                Vec3::Zero(), -1.0);
                else if (right >= 0)
                    firstAt = closestInTwoBalls(
                        firstAt, m_local[static_cast<size_t>(right)] - lastOffset,
                        margin * reachBetween(*this, a->last, right), Vec3::Zero(), -1.0);
                const Vec3 shift = firstAt - (frame.apply(a->localPoints.front()) - m_origin);
                // (Without a budget a try part of the way counts as brought into reach.)
                const Vec3 whole = a->frame.apply(a->localPoints.front()) - m_origin;
                broughtIntoReach =
                    broughtIntoReach || (firstAt - (bounded ? wanted : whole)).squaredNorm() > 0.0;
                for (int j = a->first; j <= a->last; ++j)
                    m_local[static_cast<size_t>(j)] =
                        frame.apply(a->localPoints[static_cast<size_t>(j - a->first)]) - m_origin +
                        shift;
                // Warm start towards the other fixed points (see blendSide).
                blendSide(a->first, -1, m_local[first] - oldFirst);
                blendSide(a->last, +1, m_local[last] - oldLast);
            }
        };
        // (Plain ints, not a structured binding: tryPlacing captures them, which clang refuses.)
        const std::pair<int, int> pinned = pinnedRange(m_attachments, -1);
        const int lo = pinned.first, hi = pinned.second;
        PinnedSpans spans(*this, lo, hi, -1);
        // Every segment between the pinned points in its band, and every joint no farther beyond
        // its limit than `allowed` (radians; kNoBendLimit: any turn).
        constexpr double kNoBendLimit = std::numeric_limits<double>::infinity();
        const auto spansHold = [&](double allowed) {
            for (int seg = lo; seg < hi; ++seg) {
                const size_t k = static_cast<size_t>(seg);
                const double l = (m_local[k + 1] - m_local[k]).norm();
                if (!(std::max(l - m_maxLength[k], m_minLength[k] - l) <= 1e-9 * m_restLength[k]))
                    return false;
            }
            if (allowed < kNoBendLimit)
                for (int j = lo + 1; j < hi; ++j)
                    if (turnExcess(static_cast<size_t>(j), m_local) > allowed) return false;
            return true;
        };
        // The largest turn beyond its limit of the joints between the pinned points.
        const auto bendExcess = [&](const std::vector<Vec3>& points) {
            double worst = 0.0;
            for (int j = lo + 1; j < hi; ++j)
                worst = std::max(worst, turnExcess(static_cast<size_t>(j), points));
            return worst;
        };
        // One try: the attachments placed at `fraction` of the way, the spans solved within
        // `share` Newton steps of the budget (any without one). A try cut short by the budget is
        // kept only when valid.
        const auto tryPlacing = [&](double fraction, int share) {
            place(fraction);
            const bool cutBefore = m_budgetCut;
            m_budgetCut = false;
            BudgetShare budgetShare(*this, share);
            // Where the ends leave no shape within the bend limits the bends give way (a kink).
            bool found = spans.solveBowingOrKinking(result.iterations, !broughtIntoReach);
            // A segment between two pinned points (two clips slid next to each other) is placed
            // by them alone: outside its band, no shape.
            for (int seg = lo; found && seg < hi; ++seg) {
                const size_t k = static_cast<size_t>(seg);
                const double l = (m_local[k + 1] - m_local[k]).norm();
                found =
                    !(std::max(l - m_maxLength[k], m_minLength[k] - l) > 1e-9 * m_restLength[k]);
            }
            // Under a budget only a valid shape is progress (the bends never give way): every
            // segment between the pinned points in its band, every joint within its limit or
            // (a start whose bends gave way) no farther beyond it than in the shape the try
            // started from (the tails follow after the tries).
            const bool holds =
                found && (m_budgetLeft >= 0 ? spansHold(std::max(1e-9, bendExcess(base)))
                                            : measureViolation().status == Status::Ok);
            if (m_budgetLeft >= 0 && !holds) found = false;
            if (holds) spans.relaxCompressedBends(result.iterations);
            m_budgetCut = cutBefore || m_budgetCut;
            return found;
        };
        // Under a budget, once kStalledMoves updates in a row advanced nothing: a try whose bends
        // give way (the chain projection, soft bends, then the lengths alone, within `share`
        // steps), kept when every length between the pinned points is in its band.
        const auto tryGivingWay = [&](double fraction, int share) {
            place(fraction);
            const bool cutBefore = m_budgetCut;
            m_budgetCut = false;
            BudgetShare budgetShare(*this, share);
            static_cast<void>(spans.bendsGiveWay(result.iterations, true));
            m_budgetCut = cutBefore || m_budgetCut;
            return spansHold(kNoBendLimit);
        };
        bool solved = false;
        if (m_budgetLeft < 0) {
            for (const double fraction : kFractions) {
                solved = tryPlacing(fraction, 0);
                if (fraction < 1.0 && solved) partialMove = true;
                if (solved) break;
            }
        } else {
            // Under a budget: tries from the fraction of the way that last worked (the whole way
            // at first), halved after a try that finds no shape (each with half of the steps
            // left; the least fraction with all of them), and after one that does, from the
            // shape it reached, twice the fraction of what is left of the way, while steps are
            // left. The rest of the way follows in the next updates.
            // Giving way (kStalledMoves): the same tries, each letting the bends give way.
            double fraction = m_moveFraction;
            bool progressed = false;
            while (true) {
                const bool least = fraction <= kLeastMoveFraction;
                const int share = BudgetShare::half(*this, least);
                const bool tried = m_moveStall.givingWay ? tryGivingWay(fraction, share)
                                                         : tryPlacing(fraction, share);
                if (tried) {
                    progressed = true;
                    budgetedLong = budgetedLong || !least;
                    m_moveFraction = std::min(1.0, 2.0 * fraction);
                    if (fraction >= 1.0) {
                        partialMove = false;
                        break;
                    }
                    partialMove = true;
                    base = m_local;
                    fraction = m_moveFraction;
                } else {
                    m_local = base;
                    if (least) {
                        if (!progressed) m_moveFraction = kLeastMoveFraction;
                        leastFailed = true;
                        break;
                    }
                    fraction = std::max(kLeastMoveFraction, 0.5 * fraction);
                    if (!progressed) m_moveFraction = fraction;
                }
                if (m_budgetLeft < kLeastMoveSteps) break;
            }
            solved = progressed;
            budgetedProgress = budgetedProgress || progressed;
        }
        beyondReach = broughtIntoReach;
        if (!solved) {
            // Nothing valid found: the hose stays (its attachments unmet), its clips where they
            // were.
            m_local = m_scratch;
            if (clips) restoreClips();
        }
        // The tails beyond the pinned range as it is now (the clips restored or not).
        const auto [tailsFrom, tailsTo] = pinnedRange(m_attachments, -1);
        Solver tails(*this);
        tails.sweepTails(tailsFrom, tailsTo, m_scratch, wasInvalid);
        violation = measureViolation();
        if (solved && m_moveStall.givingWay && m_budgetLeft >= 0) break; // (the bends gave way)
        if (violation.status == Status::Ok) {
            if (solved || !clipMoved || attempt >= margins) break;
            attempt = margins - 1; // not solved from the slide as it was: from the moved one
        }
    }
    result.lengthViolation = violation.lengthViolation;
    result.angleViolation = violation.angleViolation;
    double gap = 0.0;
    for (const Attachment* a : targets)
        gap = std::max(gap, attachmentGap(a->id));
    result.status =
        (violation.status != Status::Ok || gap > 1e-9) ? Status::Infeasible : Status::Ok;
    // Under a budget: kStalledMoves updates in a row that advanced by the least fraction alone
    // and gained less than kStalledMoveGain, or not at all, let the bends give way in the next
    // ones, and as many more giving way end the move where it is (it rests) unless the ones
    // before crept (back to them).
    const bool bounded = m_budgetLeft >= 0;
    const bool advanced = budgetedProgress && (m_moveStall.givingWay || budgetedLong ||
                                               gap < (1.0 - kStalledMoveGain) * gapBefore);
    // (Nothing found before the least fraction was tried is no stall: the next update goes on
    // from a shorter fraction.)
    const bool stalled = !advanced && (budgetedProgress || leastFailed);
    if (gap <= 1e-9) {
        m_moveStall = MoveStall{};
    } else if (bounded && advanced) {
        m_moveStall.count = 0;
        if (!m_moveStall.givingWay) m_moveStall.crept = false;
    } else if (bounded && stalled && !m_moveStall.givingWay) {
        m_moveStall.crept = m_moveStall.crept || budgetedProgress;
        if (++m_moveStall.count >= kStalledMoves) {
            m_moveStall.givingWay = true;
            m_moveStall.count = 0;
            m_moveFraction = 1.0; // giving way, the whole way first
        }
    } else if (bounded && stalled && ++m_moveStall.count >= kStalledMoves && m_moveStall.crept) {
        // Giving way advanced nothing where the tries that keep the bends crept: back to those.
        m_moveStall = MoveStall{};
    }
    const bool resting = m_moveStall.givingWay && m_moveStall.count >= kStalledMoves;
    // Under a budget: short of frames within reach for want of steps, or until a stall gives
    // way or rests, pending (Ok while the hose is valid); step() goes on with it.
    if (bounded && gap > 1e-9 && !resting && (m_budgetCut || partialMove || !budgetedProgress)) {
        result.pending = true;
        result.remaining = gap;
        if (violation.status == Status::Ok && !beyondReach) result.status = Status::Ok;
    }
    m_dirtyViolation = violation.status != Status::Ok;
    for (size_t i = 0; i < m_local.size(); ++i)
        result.movedPoints += m_local[i] != m_scratch[i];
    ++m_revision;
    return result;
}

UpdateResult Hose::settle()
{
    BudgetScope unbounded(*this, false);
    return settleFrom(-1);
}

bool Hose::closeSpans(int held, const std::vector<Vec3>& before, int& iterations)
{
    const auto [lo, hi] = pinnedRange(m_attachments, held);
    if (lo > hi) return false;
    PinnedSpans spans(*this, lo, hi, held);
    spans.spanSteps = kCloseSpanSteps;
    if (!spans.hard(iterations)) return false;
    followTails(held, before);
    return measureViolation().status == Status::Ok;
}

std::pair<int, int> Hose::pinnedRangeOf(int held) const
{
    return pinnedRange(m_attachments, held);
}

void Hose::followTails(int held, const std::vector<Vec3>& before)
{
    const auto [lo, hi] = pinnedRangeOf(held);
    if (lo > hi) return;
    Solver tails(*this);
    tails.sweepTails(lo, hi, before, true);
}

UpdateResult Hose::settleFrom(int held)
{
    if (held >= pointCount() || (held >= 0 && m_fixed[static_cast<size_t>(held)])) held = -1;
    auto [lo, hi] = pinnedRange(m_attachments, held);
    if (lo > hi) lo = hi = 0; // nothing fixed: hold point 0 and let the rest follow
    m_scratch = m_local;
    UpdateResult result;
    PinnedSpans spans(*this, lo, hi, held);
    if (!spans.solveBowingOrKinking(result.iterations)) m_local = m_scratch;
    Solver tails(*this);
    tails.sweepTails(lo, hi, m_scratch, true);
    const UpdateResult violation = measureViolation();
    result.status = violation.status;
    result.lengthViolation = violation.lengthViolation;
    result.angleViolation = violation.angleViolation;
    m_dirtyViolation = violation.status != Status::Ok;
    for (size_t i = 0; i < m_local.size(); ++i)
        result.movedPoints += m_local[i] != m_scratch[i];
    ++m_revision;
    return result;
}

} // namespace chaintube
