// SpanSolver::advance: a span's point brought towards its target in steps that each end valid
// (a trust radius on the sub-goal), with reach() for a target beyond the span's reach.
#include "span_solver.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace chaintube::detail {

namespace {

/// SpanSolver::advance: the least gain (of a segment) of a step along the edge of the
/// reachable set.
constexpr double kEdgeGain = 1e-3;
/// SpanSolver::advance: a hard sub-goal is given up after this many undone Newton steps. Its
/// Newton steps converge from the step's warm start when the sub-goal is reachable (of the hard
/// tries that arrive, about 5 % have one step undone on the way); an undone step is the sign of
/// a sub-goal out of reach, and the soft try follows.
constexpr int kHardTryRejects = 1;
/// SpanSolver::advance: a goal within this many segments of the last grab's is the same goal (a
/// held target), whose trust radius goes on from where that grab left it.
constexpr double kHeldGoal = 1e-3;
/// SpanSolver::advance: a sub-goal farther than this many segments whose hard try failed is
/// tried again at half the distance before any soft try.
constexpr double kFarSubGoal = 8.0;
/// SpanSolver::advance: steps towards a target that moved when the last grab of the point got it
/// no nearer (it stays at the edge of its reach while the target moves beyond it: the steps after
/// a first one that fails gain nothing either, in nearly every frame).
constexpr int kStalledSteps = 1;
/// SpanSolver::reach: the step's metric at the start of a call, σ of σ·rest² per squared turn
/// (σ per squared length change); a quarter after a step taken, four times after one undone.
constexpr double kReachMetric = 10.0;

} // namespace

SpanSolver::Outcome SpanSolver::advance(int root, int end, const Vec3& endTarget,
                                        std::vector<SpanGoal> goals, int moving, const Vec3& target,
                                        const Vec3* rootDirection, const Vec3* endDirection,
                                        int maxSteps, int movingSteps, int stepIterations,
                                        double tolerance, const Vec3* requested)
{
    Outcome out;
    out.valid = true;
    std::vector<Vec3>& p = h.m_local;
    const int dir = end > root ? 1 : -1;
    const int point = moving >= 0 ? goals[static_cast<size_t>(moving)].point : end;
    const double rest = h.m_restLength[static_cast<size_t>(dir > 0 ? end - 1 : end)];
    // At most maxSteps steps. A target that moved since the last grab of this point: from a whole
    // trust radius, ending after movingSteps steps that brought the point nearer (what they leave
    // is covered by the next grabs), and after kStalledSteps when that grab got the point no
    // nearer. A held target (the last grab of this point stopped short of the same goal, to
    // kHeldGoal of a segment): from the radius that grab ended with, keeping the short steps that
    // arrive along the edge of the reachable set instead of halving down to them again each call.
    const bool samePoint = moving >= 0 && h.m_trustCarry.point == point;
    const bool held = samePoint && (target - h.m_trustCarry.goal).norm() <= kHeldGoal * rest;
    double radius = held ? h.m_trustCarry.radius : std::numeric_limits<double>::infinity();
    double reachMetric = held ? h.m_trustCarry.reachMetric : 0.0;
    if (samePoint && !held && h.m_trustCarry.stalled) maxSteps = std::min(maxSteps, kStalledSteps);
    int gained = 0;          // steps that brought the point nearer
    bool softFailed = false; // a soft try that brought it no nearer
    for (int step = 0; step < maxSteps && (held || gained < movingSteps); ++step) {
        if (h.m_budgetLeft == 0) { // the update's budget is spent: the span stays valid as it is
            h.m_budgetCut = true;
            break;
        }
        const Vec3 at = p[static_cast<size_t>(point)];
        const double error = (target - at).norm();
        // Nearer the target by `gain` (relative to a segment). Beyond reach, nearer the
        // requested target by kEdgeGain of a segment: smaller gains are a creep along the edge
        // of the reachable set that would keep a held target from coming to rest.
        auto progress = [&](const Vec3& q, double gain) {
            if (!requested) return (target - q).norm() < error - gain * rest;
            return (target - q).norm() < error - 1e-12 * rest &&
                   (*requested - q).norm() <= (*requested - at).norm() - kEdgeGain * rest;
        };
        if (error <= tolerance * rest) {
            // There to the tolerance: exactly there (the adjacent segments change by as much).
            p[static_cast<size_t>(point)] = target;
            out.goalsMet = true;
            break;
        }
        const double distance = std::min(radius, error); // to the sub-goal
        const Vec3 subGoal = error <= radius ? target : Vec3(at + (target - at) * (radius / error));
        if (moving >= 0) goals[static_cast<size_t>(moving)].target = subGoal;
        const int lo = std::min(root, end), hi = std::max(root, end);
        m_saved.assign(p.begin() + lo, p.begin() + hi + 1);
        // Towards a target beyond the reach balls (clamped to 1e-6 inside them: reaching it
        // would take the span nearly straight, which the bends at its ends do not allow), the
        // hard try from a whole trust radius fails: the soft try alone. So, too, at any radius,
        // when the target moved on while the last grab got the point no nearer (it stays at the
        // edge of its reach). A far target keeps the hard try, whose failure halves the way.
        const bool softOnly = requested && !held &&
                              ((samePoint && h.m_trustCarry.stalled) ||
                               (step == 0 && distance <= kFarSubGoal * rest));
        if (moving >= 0 && !softOnly) {
            // Warm start: the step's displacement spread over the span, fading to nothing at
            // its ends (and at the other goals), so the solve starts near a shape that has
            // the point at its sub-goal instead of at a corner of the bend limits.
            const Vec3 shift = subGoal - at;
            int left = lo, right = hi;
            for (const SpanGoal& g : goals) {
                if (g.point < point) left = std::max(left, g.point);
                if (g.point > point) right = std::min(right, g.point);
            }
            for (int i = left + 1; i < right; ++i) {
                const double weight = i <= point ? double(i - left) / (point - left)
                                                 : double(right - i) / (right - point);
                p[static_cast<size_t>(i)] += weight * shift;
            }
        }
        if (!softOnly) {
            const Outcome o =
                solve(root, end, true, moving >= 0 ? endTarget : subGoal, goals, rootDirection,
                      endDirection, stepIterations, tolerance, false, kHardTryRejects);
            out.iterations += o.iterations;
            if (o.valid && progress(moving >= 0 ? p[static_cast<size_t>(point)] : subGoal, 1e-12)) {
                if (moving < 0) p[static_cast<size_t>(point)] = subGoal;
                if (o.goalsMet) radius = 2.0 * distance;
                ++gained;
                continue;
            }
            std::copy(m_saved.begin(), m_saved.end(), p.begin() + lo);
        }
        radius = 0.5 * distance;
        // A far sub-goal is tried again at half the distance, without the soft try: that gains
        // about a hundredth of the way a Newton step (its goal rows damped), nothing worth its
        // steps this far out, and a grab that ended after it would leave a fine hose lagging
        // behind its target frame after frame.
        if (distance > kFarSubGoal * rest && step + 1 < maxSteps) continue;
        // A soft try that brought the point no nearer in this call is not made again at a
        // nearer sub-goal: at the edge of the reachable set it gains nothing there either.
        if (softFailed) continue;
        if (moving >= 0 && held) {
            // A held target: SQP steps towards the closest reachable shape (reach()), with what
            // is left of the call's budget; they end the call.
            if (!(reachMetric > 0.0)) reachMetric = kReachMetric;
            const Outcome steps =
                reach(root, end, endTarget, goals, moving, requested ? *requested : target,
                      rootDirection, endDirection, 2 * maxSteps * stepIterations - out.iterations,
                      tolerance, reachMetric);
            out.iterations += steps.iterations;
            if (steps.valid && progress(p[static_cast<size_t>(point)], kEdgeGain))
                ++gained;
            else
                std::copy(m_saved.begin(), m_saved.end(), p.begin() + lo);
            break;
        }
        // The sub-goal is out of the span's reach (bend limits and the fixed segments' tangents
        // make the reachable set smaller than the balls of the grab's reach): the point goes as
        // near it as the span allows, the end still hard, so a held target keeps coming nearer
        // instead of stalling at the first unreachable sub-goal.
        if (moving >= 0) goals[static_cast<size_t>(moving)].hard = false;
        const Outcome soft = solve(root, end, moving >= 0, moving >= 0 ? endTarget : subGoal, goals,
                                   rootDirection, endDirection, stepIterations, tolerance);
        if (moving >= 0) goals[static_cast<size_t>(moving)].hard = true;
        out.iterations += soft.iterations;
        // A soft step counts when it gains kEdgeGain of a segment (the same creep).
        if (soft.valid && progress(p[static_cast<size_t>(point)], kEdgeGain)) {
            ++gained;
        } else {
            std::copy(m_saved.begin(), m_saved.end(), p.begin() + lo);
            softFailed = true;
        }
    }
    if (!out.goalsMet && (target - p[static_cast<size_t>(point)]).norm() <= tolerance * rest) {
        p[static_cast<size_t>(point)] = target;
        out.goalsMet = true;
    }
    if (moving >= 0 && !out.goalsMet)
        h.m_trustCarry = {point, std::min(radius, (target - p[static_cast<size_t>(point)]).norm()),
                          target, gained == 0, reachMetric};
    else if (moving >= 0)
        h.m_trustCarry = Hose::TrustCarry{};
    return out;
}

} // namespace chaintube::detail
