// Gravity (beyond the paper): one implicit step per frame through the chain projection, and
// sag(), which steps until the hose is at rest.
#include "budget.h"
#include "chaintube/hose.h"
#include "projection.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <tuple>

namespace chaintube {

namespace {
constexpr double kGravity = 9.81; ///< m/s²
/// Fraction of the velocity a step of Gravity::kFrameSeconds carries on; a step of t seconds
/// carries on kDamping^(t / kFrameSeconds), so the damping per second is the same for every
/// step length.
constexpr double kDamping = 0.9;
constexpr int kStepProjectionSteps = 8; ///< Newton steps of one attempt
/// The attempts of one step: the full prediction, then from rest with the fall scaled by the
/// hose's retry fall, by a quarter of it and, when that quarter is above kLeastFall, by
/// kLeastFall (a smaller move from the valid start is nearer the constraints, so Newton's
/// quadratic convergence reaches them within the attempt's steps). The retry fall is the last
/// one that worked, never below kLeastFall; a step whose full prediction works lets it grow by
/// kFallGrowth (at most the full fall).
constexpr double kFallShrink = 0.25;
constexpr double kLeastFall = 1.0 / 16.0;
constexpr double kFallGrowth = 4.0;
/// Once a full prediction of a hose with a held point failed, this many steps skip it before it
/// is tried again: they start with the retry fall and the velocity.
constexpr int kSkipFullSteps = 8;
/// The free tails' velocity correction (Hose::step): a little more than follow-the-leader's
/// full correction, with which a 99-segment cantilever falls as the coarse ones do
/// (GravityStep.ACantileverFallsAlike…).
constexpr double kTailCorrection = 1.1;
constexpr double kStepConverged = 1e-10; ///< relative length, radians, contact depth
/// Largest violation left by the projection that the span solver closes (relative length,
/// radians): its moves are then of the order of the violation, so contacts stay respected.
constexpr double kCloseFrom = 1e-5;
/// Without contacts, while a point is held: the violation at which the projection stops and
/// the span solver closes the rest (checked by kCloseMove); the fewest instructions a frame of
/// 1e-5 … 1e-2 (tests/bench/PERFORMANCE-NOTES.md, "Grabs between fixed points").
constexpr double kCloseFromFree = 1e-3;
/// Farther off, without contacts: the largest move (of the mean rest length) that closing may
/// make from the projection's state.
constexpr double kCloseMove = 0.05;
/// Of the mean rest length, per step of Gravity::kFrameSeconds (a shorter step: its share).
constexpr double kSettledMotion = 1e-6;
constexpr double kStill = 1e-12; ///< of the mean rest length: a held point that has not moved
constexpr double kStallSeconds = 120.0 * Gravity::kFrameSeconds; ///< without coming lower: at rest
constexpr double kHover = 0.01; ///< of the mean rest length, in mean height
/// Under a budget: gravity steps in a row cut short by it that found nothing valid, after which
/// the hose rests where it is as it does without a budget (no longer pending).
constexpr int kStalledFalls = 3;
} // namespace

/// One implicit step: the predicted positions (inertia, damping, gravity) projected onto the
/// constraints (lengths, bends, contacts) as the mass-weighted closest valid state.
class GravityStep
{
public:
    GravityStep(Hose& hose, int heldPoint) : h(hose), projection(hose), held(heldPoint)
    {
        projection.setRange(0, h.pointCount() - 1);
        projection.useMassesFromRestLengths(heldPoint);
        meanRest = h.restLengthTotal() / h.segmentCount();
        std::tie(pinnedFirst, pinnedLast) = h.pinnedRangeOf(heldPoint);
    }

    /// Contacts of the free points with the colliders near their predicted positions: the
    /// tangent plane at the closest point of a collider, which the point must stay
    /// outerRadius() (and a tenth of the collision tolerance) above.
    void gatherContacts(const std::vector<Vec3>& predicted, const std::vector<Vec3>& from)
    {
        projection.clearContacts();
        touching.assign(predicted.size(), 0);
        if (h.m_colliders.empty()) return;
        radius = h.outerRadius() + 0.1 * h.m_collisionOptions.tolerance;
        const double reach = radius + h.m_collisionOptions.tolerance + meanRest;
        Aabb box;
        for (const Vec3& point : predicted)
            box.extend(point + h.m_origin);
        box.min.array() -= reach;
        box.max.array() += reach;
        const std::vector<double>& w = projection.inverseMass();
        for (const auto& collider : h.m_colliders) {
            const Aabb bounds = collider->worldBounds();
            if ((bounds.min.array() > box.max.array()).any() ||
                (bounds.max.array() < box.min.array()).any())
                continue;
            for (size_t i = 0; i < predicted.size(); ++i) {
                if (w[i] == 0.0) continue;
                const MeshCollider::Closest c =
                    collider->closestToPoint(predicted[i] + h.m_origin, reach);
                if (c.found && projection.setContact(static_cast<int>(i), c, h.m_origin, from[i],
                                                     radius, 1e-12 * meanRest))
                    touching[i] = 1;
            }
        }
    }

    /// Projects `predicted` (written into the hose) onto the constraints by the fast
    /// projection (Goldenthal et al. 2007): Newton steps of the smallest mass-weighted move onto
    /// the linearised constraints, from the predicted positions, at most kStepProjectionSteps.
    /// Where they end close but not within the tolerance, the span solver closes the rest
    /// exactly (Hose::closeSpans): its moves are then of the order of the violation. Without
    /// contacts, it also closes from farther off when that moves no point by more than
    /// kCloseMove of a segment. While a point is held and moves, the projection stops as soon as
    /// closing can take over (within kCloseFrom, or kCloseFromFree without contacts): its last
    /// steps often converge only linearly there, bend limits switching on and off near their
    /// bounds, and closing costs less than they do; a hose settling on its own, or held by a
    /// point that has not moved since the last step (without contacts), converges to the
    /// tolerance (closing would cost more than its last steps, and a close from 1e-3 moves the
    /// points by more than the violation, so a hose held still would never come to rest).
    /// Returns whether every constraint holds afterwards.
    bool project(const std::vector<Vec3>& predicted, const std::vector<Vec3>& from, int& iterations)
    {
        gatherContacts(predicted, from);
        h.m_local = predicted;
        const bool contacts =
            std::any_of(touching.begin(), touching.end(), [](unsigned char t) { return t != 0; });
        const double stopAt = held < 0    ? kStepConverged
                              : contacts  ? kCloseFrom
                              : heldStill ? kStepConverged
                                          : kCloseFromFree;
        const detail::ProjectionOutcome out = projection.run(kStepProjectionSteps, stopAt);
        iterations += out.iterations;
        measuredValid = false;
        if (out.violation <= std::min(stopAt, kCloseFrom)) {
            measured = h.measureViolation();
            measuredValid = measured.status == Status::Ok;
            if (measuredValid) return true;
        }
        if (out.violation <= kCloseFrom) return h.closeSpans(held, from, iterations);
        // Farther off and without contacts (nothing to push into): closed too when that moves
        // no point more than kCloseMove of a segment from where the projection left it (a
        // larger correction would be a jump, not a fall).
        if (contacts) return false;
        projected = h.m_local;
        if (!h.closeSpans(held, from, iterations)) return false;
        double moved = 0.0;
        for (size_t i = 0; i < projected.size(); ++i)
            moved = std::max(moved, (h.m_local[i] - projected[i]).norm());
        return moved <= kCloseMove * meanRest;
    }

    /// The free tails beyond the outermost pinned points (which a step never moves), when none
    /// touches a collider, may fall on their own: left out of the projection (inverse mass 0, so
    /// they stay where they were during its attempts), they follow by the paper's pass from their
    /// full prediction afterwards (Hose::step). Returns whether there are any.
    bool separateTails()
    {
        if (pinnedFirst > pinnedLast || (pinnedFirst == 0 && pinnedLast == h.pointCount() - 1))
            return false;
        first = pinnedFirst;
        last = pinnedLast;
        // A tail with a contact near its prediction stays in the projection (its contact rows).
        for (size_t i = 0; i < touching.size(); ++i)
            if (touching[i] && isTail(i)) {
                first = 0;
                last = std::numeric_limits<int>::max();
                return false;
            }
        std::vector<double>& w = projection.inverseMass();
        for (int i = 0; i < h.pointCount(); ++i)
            if (isTail(static_cast<size_t>(i))) w[static_cast<size_t>(i)] = 0.0;
        return true;
    }

    /// Whether every point from the first to the last pinned one is fixed or held (a hose
    /// hanging from one attachment or the held point: its tails are all that falls). The
    /// points in that range keep their inverse masses (separateTails() zeroes only the tails').
    bool onlyTailsFall()
    {
        if (pinnedFirst > pinnedLast) return false;
        const std::vector<double>& w = projection.inverseMass();
        for (int i = pinnedFirst; i <= pinnedLast; ++i)
            if (w[static_cast<size_t>(i)] != 0.0) return false;
        return true;
    }

    bool isTail(size_t i) const
    {
        return static_cast<int>(i) < first || static_cast<int>(i) > last;
    }

    Hose& h;
    detail::ChainProjection projection;
    int held;
    /// The held point has not moved since the last step (a hand holding still): the projection
    /// converges as a hose settling on its own does, so the hose comes to rest.
    bool heldStill = false;
    int pinnedFirst = 0, pinnedLast = -1;                  ///< Hose::pinnedRangeOf(held)
    int first = 0, last = std::numeric_limits<int>::max(); ///< separateTails(): the pinned range
    std::vector<Vec3> tailCorrection; ///< taken off the tails' velocity (Hose::step)
    double meanRest = 0.0;
    double radius = 0.0;
    std::vector<unsigned char> touching;
    std::vector<Vec3> projected; ///< project(): the projection's state before it is closed
    /// project(): the hose's violation as it returned true without closing (measuredValid),
    /// which Hose::step reports when nothing moves after it.
    UpdateResult measured;
    bool measuredValid = false;
};

SagResult Hose::sag(const SagOptions& options)
{
    SagResult result;
    const Vec3 direction = options.gravityDirection;
    const bool anyFixed =
        std::any_of(m_fixed.begin(), m_fixed.end(), [](unsigned char f) { return f != 0; });
    if (!direction.allFinite() || !(direction.norm() > 0.0) || !anyFixed || options.maxRounds < 0 ||
        !(options.tolerance > 0.0)) {
        result.update.status = Status::InvalidInput;
        return result;
    }
    BudgetScope unbounded(*this, false); // sag() settles fully, whatever the budget
    const Gravity gravity = m_spec.gravity;
    const int held = m_held;
    m_spec.gravity.enabled = true;
    m_spec.gravity.direction = direction;
    m_held = -1;
    markSettled();
    m_settledRevision = 0;
    for (result.rounds = 0; result.rounds < options.maxRounds; ++result.rounds) {
        const std::uint64_t revision = m_revision;
        result.update = step();
        if (m_settledRevision == m_revision || m_revision == revision) {
            result.settled = true;
            break;
        }
    }
    m_spec.gravity = gravity;
    m_held = held;
    markSettled();
    m_settledRevision = 0;
    result.update = measureViolation();
    return result;
}

void Hose::releaseGrab()
{
    if (m_held < 0) return;
    m_held = -1;
    m_trustCarry = TrustCarry{};
    m_pendingGrab = false;
    m_settledRevision = 0; // step(): the released point may fall
}

void Hose::markSettled()
{
    m_gravityPrevious.clear();
    m_gravityLast.clear();
    m_gravityInputRevision = 0;
    m_gravityLowestEnergy = 0.0;
    m_gravityStallSeconds = 0.0;
    m_gravityStalls = 0;
    m_gravityStepSeconds = Gravity::kFrameSeconds;
    m_gravityRetryFall = 1.0;
    m_gravityFullFailed = false;
    m_gravitySkippedFull = 0;
    m_settledRevision = m_revision;
}

UpdateResult Hose::step()
{
    return step(Gravity::kFrameSeconds);
}

namespace {
bool didSomething(const UpdateResult& result)
{
    return result.iterations > 0 || result.movedPoints > 0 || result.pending;
}
} // namespace

UpdateResult Hose::step(double seconds)
{
    if (!std::isfinite(seconds) || !(seconds > 0.0) || seconds > Gravity::kMaxFrameSeconds) {
        UpdateResult refused;
        refused.status = Status::InvalidInput;
        return refused;
    }
    BudgetScope scope(*this);
    // A grab or attachment move cut short by the budget goes on, unless a new one came in since
    // the last step (the same frame's work).
    UpdateResult pending;
    if ((m_pendingGrab || m_pendingMove) && !m_updatedSinceStep) pending = continuePending();
    m_updatedSinceStep = false;
    // Equal steps of at most kFrameSeconds (the tolerance keeps 1/45 s at two steps).
    const int steps =
        std::max(1, static_cast<int>(std::ceil(seconds / Gravity::kFrameSeconds - 1e-9)));
    const double stepSeconds = seconds / steps;
    UpdateResult gravity;
    for (int k = 0; k < steps; ++k) {
        // Under a budget the steps take what the frame has left in turn; none left: the frame's
        // later steps are dropped, the hose pending (the next step() goes on from here).
        if (k > 0 && m_budgetLeft == 0) {
            m_pendingFall = gravity.pending = true;
            break;
        }
        const UpdateResult one = stepGravity(stepSeconds);
        if (!didSomething(one)) { // at rest, or gravity off: so are the frame's later steps
            if (k == 0) gravity = one;
            break;
        }
        const int iterations = gravity.iterations + one.iterations;
        const int moved = std::max(gravity.movedPoints, one.movedPoints);
        const bool blocked = gravity.blocked || one.blocked;
        gravity = one; // the shape the frame leaves
        gravity.iterations = iterations;
        gravity.movedPoints = moved;
        gravity.blocked = blocked;
        if (one.pending) break; // the budget ran out: the frame's later steps are dropped
    }
    if (!didSomething(gravity)) {
        if (pending.iterations > 0 || pending.movedPoints > 0 || pending.pending) return pending;
        return gravity;
    }
    gravity.status = std::max(gravity.status, pending.status);
    gravity.grabError = pending.grabError;
    gravity.movedPoints = std::max(gravity.movedPoints, pending.movedPoints);
    gravity.iterations += pending.iterations;
    gravity.pending = gravity.pending || pending.pending;
    gravity.remaining = std::max(gravity.remaining, pending.remaining);
    return gravity;
}

UpdateResult Hose::stepGravity(double seconds)
{
    BudgetScope scope(*this);
    m_pendingFall = false;
    UpdateResult result;
    if (!m_spec.gravity.enabled || m_settledRevision == m_revision) return result;
    const size_t n = m_local.size();
    const bool anyFixed =
        std::any_of(m_fixed.begin(), m_fixed.end(), [](unsigned char f) { return f != 0; });
    if (!anyFixed && m_held < 0) {
        m_settledRevision = m_revision; // nothing to hang from
        return result;
    }
    if (m_gravityPrevious.size() != n || m_gravityLast.size() != n) {
        m_gravityPrevious = m_local;
    } else {
        // Moves made since the last step (grabs, attachments) carry no velocity: shift the
        // previous positions with them, so a drag never flings the hose.
        for (size_t i = 0; i < n; ++i)
            m_gravityPrevious[i] += m_local[i] - m_gravityLast[i];
    }
    const bool inputChanged = m_gravityInputRevision != m_revision;
    detail::Workspace& workspace = m_workspace.get();
    workspace.gravityStart = m_local;
    const std::vector<Vec3>& start = workspace.gravityStart;
    GravityStep engine(*this, m_held);
    // Still: moved by no more than rounding (a grab of the same target may place the point
    // again through the span's kinematics).
    engine.heldStill =
        m_held >= 0 && m_gravityLast.size() == n &&
        (m_local[static_cast<size_t>(m_held)] - m_gravityLast[static_cast<size_t>(m_held)])
                .norm() <= kStill * engine.meanRest;
    const std::vector<double>& w = engine.projection.inverseMass();
    if (m_dirtyViolation) {
        // The shape violates its constraints (bends that gave way to an attachment move, a shape
        // built in violation): this step brings it nearer to valid instead of falling, from
        // rest, and is kept only if it leaves the worst violation smaller.
        const UpdateResult before = measureViolation();
        if (before.status != Status::Ok) {
            engine.gatherContacts(start, start);
            const detail::ProjectionOutcome out =
                engine.projection.run(kStepProjectionSteps, kStepConverged);
            result.iterations = std::max(out.iterations, 1);
            if (out.violation <= kCloseFrom)
                static_cast<void>(closeSpans(m_held, start, result.iterations));
            UpdateResult after = measureViolation();
            if (after.lengthViolation > std::max(before.lengthViolation, 1e-9)) {
                // Lengths first: the bends give way again where the projection could not make
                // both hold (as in an attachment move), so no step trades bends for lengths.
                engine.projection.setBends(false);
                const detail::ProjectionOutcome lengths =
                    engine.projection.run(kStepProjectionSteps, kStepConverged);
                engine.projection.setBends(true);
                result.iterations += lengths.iterations;
                after = measureViolation();
            }
            const bool lengthsHold =
                after.lengthViolation <= std::max(before.lengthViolation, 1e-9);
            const double worstBefore = std::max(before.lengthViolation, before.angleViolation);
            if (!lengthsHold ||
                !(std::max(after.lengthViolation, after.angleViolation) < worstBefore)) {
                m_local = start; // no nearer within the budget: it stays until an input changes
                m_gravityPrevious = start;
                m_gravityLast = start;
                UpdateResult stayed = before;
                stayed.iterations = result.iterations;
                // (The update's budget ran out: the next step goes on, kStalledFalls times.)
                if (scope.cut() && ++m_gravityStalls < kStalledFalls) {
                    m_pendingFall = stayed.pending = true;
                    return stayed;
                }
                m_gravityStalls = 0;
                m_settledRevision = m_revision;
                return stayed;
            }
            ++m_revision;
            m_gravityStalls = 0;
            m_dirtyViolation = after.status != Status::Ok;
            m_gravityPrevious = m_local;
            m_gravityLast = m_local;
            m_gravityInputRevision = m_revision;
            result.status = after.status;
            result.lengthViolation = after.lengthViolation;
            result.angleViolation = after.angleViolation;
            for (size_t i = 0; i < n; ++i)
                result.movedPoints += m_local[i] != start[i] ? 1 : 0;
            if (!m_colliders.empty()) applyCollisions(result, -1, Vec3::Zero()); // hose_contact.cpp
            return result;
        }
        m_dirtyViolation = false;
    }
    const Vec3 fall = m_spec.gravity.direction.normalized() * (kGravity * seconds * seconds);
    // The velocity carried on, as a move over this step's time (the last step may have been
    // longer or shorter), damped for this step's time.
    const double carry =
        std::pow(kDamping, seconds / Gravity::kFrameSeconds) * (seconds / m_gravityStepSeconds);
    std::vector<Vec3>& predicted = workspace.gravityPredicted;
    predicted.resize(n); // every point written before it is read
    bool valid = false;
    double factors[4] = {1.0, m_gravityRetryFall, 0.0, 0.0};
    if (m_gravityRetryFall > kLeastFall)
        factors[2] = std::max(kLeastFall, kFallShrink * m_gravityRetryFall);
    // The least fall is always among the attempts: a hose marked settled (retry fall 1) whose
    // bends sit on their limits next to its pins may take no more than that in its first step
    // (otherwise sag() would end there, at round 0, the hose not lowered).
    if (factors[2] > kLeastFall) factors[3] = kLeastFall;
    // Under a budget, after a step cut short that found nothing valid (kStalledFalls): the least
    // fall alone, with all of the budget.
    const bool leastOnly = m_gravityStalls > 0 && m_budgetLeft >= 0;
    if (leastOnly) {
        factors[0] = kLeastFall;
        factors[1] = factors[2] = factors[3] = 0.0;
    }
    // While a point is held (a grab each frame), a full prediction that failed fails again on
    // most of the next steps: the hose is held taut between pinned points (attachments, the
    // held point) and cannot take the whole fall next to them, and the projection does not
    // converge from there within its steps (the real-time walk at 100 points: 1,084 of 1,255
    // full predictions failed, 41 % of the Newton steps). So once it failed, the next
    // kSkipFullSteps steps start with the retry fall, the velocity kept. (Not without a held
    // point: a hose settling on its own keeps trying the full prediction each step; with the
    // skips a test-rig hose settled in 296 steps instead of 133 and moved a point by 0.51 of a
    // segment in one.)
    // A hose of which only the tails fall (hanging from one attachment or the held point alone)
    // goes on without the projection once its full prediction failed: its tails fall by the
    // paper's pass from their full prediction (below) whatever the projection does.
    const bool onlyTails = m_colliders.empty() && engine.onlyTailsFall();
    size_t firstAttempt = 0;
    const bool skipFull = m_held >= 0 && m_gravitySkippedFull < kSkipFullSteps;
    if (m_gravityFullFailed && (onlyTails || skipFull) && !leastOnly) {
        firstAttempt = 1;
        ++m_gravitySkippedFull;
    }
    bool tails = false;
    for (size_t attempt = firstAttempt; attempt < std::size(factors) && factors[attempt] > 0.0;
         ++attempt) {
        // Where the full prediction of the whole hose fails, its free tails fall on their own.
        if (attempt > 0 && !tails) tails = engine.separateTails();
        // Attempt 0 carries the velocity, and so does the first attempt of a step that skips it;
        // the others start from rest with a smaller fall.
        const double velocity = attempt == firstAttempt ? carry : 0.0;
        const Vec3 move = fall * factors[attempt];
        for (size_t i = 0; i < n; ++i)
            predicted[i] =
                w[i] != 0.0 ? Vec3(start[i] + velocity * (start[i] - m_gravityPrevious[i]) + move)
                            : start[i];
        {
            // Under a budget, half of what is left for each attempt but the last.
            const bool lastAttempt =
                attempt + 1 == std::size(factors) || !(factors[attempt + 1] > 0.0);
            BudgetShare share(*this, BudgetShare::half(*this, lastAttempt));
            valid = engine.project(predicted, start, result.iterations);
        }
        if (attempt == 0 && !leastOnly) {
            m_gravityFullFailed = !valid;
            m_gravitySkippedFull = 0;
        }
        if (valid) {
            m_gravityRetryFall = attempt == 0 && !leastOnly
                                     ? std::min(1.0, kFallGrowth * m_gravityRetryFall)
                                     : factors[attempt];
            break;
        }
    }
    if (tails) {
        // The tails hang from pinned points that a step does not move: their full prediction,
        // then the paper's pass outwards from the pins (exact, O(tail), every length and bend
        // held by construction).
        if (!valid) m_local = start;
        for (size_t i = 0; i < n; ++i)
            if (engine.isTail(i)) {
                m_local[i] = start[i] + carry * (start[i] - m_gravityPrevious[i]) + fall;
                predicted[i] = m_local[i];
            }
        followTails(m_held, start);
        // Follow-the-leader's velocity correction (Müller et al. 2012): a point's velocity
        // loses kTailCorrection times the correction its outward neighbour took, so the pass's
        // pull along the tail does not whip its end.
        engine.tailCorrection.assign(n, Vec3::Zero());
        double tailMotion = 0.0;
        for (size_t i = 0; i < n; ++i) {
            if (!engine.isTail(i)) continue;
            tailMotion = std::max(tailMotion, (m_local[i] - start[i]).norm());
            const size_t outward = static_cast<int>(i) > engine.last ? i + 1 : i - 1;
            if (outward < n && engine.isTail(outward))
                engine.tailCorrection[i] =
                    kTailCorrection * (m_local[outward] - predicted[outward]);
        }
        if (!valid && tailMotion > kSettledMotion * engine.meanRest) valid = true;
    }
    if (!valid) {
        // Nothing valid within the budget: the hose stays where it is, at rest, until an input
        // changes.
        m_local = start;
        m_gravityPrevious = start;
        m_gravityLast = start;
        const int iterations = result.iterations;
        result = measureViolation();
        result.iterations = iterations;
        // The update's budget ran out: not at rest, the next step goes on, unless this is the
        // kStalledFalls-th such step in a row (it rests, as without a budget).
        if (scope.cut() && ++m_gravityStalls < kStalledFalls) {
            m_pendingFall = result.pending = true;
            return result;
        }
        m_gravityStalls = 0;
        m_settledRevision = m_revision;
        return result;
    }
    // A contact is inelastic and sticks: a touching point keeps no velocity.
    m_gravityPrevious = start;
    for (size_t i = 0; i < n; ++i)
        if (engine.touching[i]) m_gravityPrevious[i] = m_local[i];
    if (!engine.tailCorrection.empty()) {
        // No tail point carries on faster than it would after falling freely from the hose's
        // highest point (the pass must not add energy).
        const Vec3 down = m_spec.gravity.direction.normalized();
        double top = -std::numeric_limits<double>::infinity();
        for (const Vec3& p : m_local)
            top = std::max(top, -down.dot(p));
        for (size_t i = 0; i < n; ++i) {
            if (!engine.isTail(i)) continue;
            m_gravityPrevious[i] += engine.tailCorrection[i];
            const double height = std::max(0.0, top + down.dot(m_local[i]));
            const double most = std::sqrt(2.0 * kGravity * height) * seconds + fall.norm();
            const Vec3 velocity = m_local[i] - m_gravityPrevious[i];
            const double speed = velocity.norm();
            if (speed > most) m_gravityPrevious[i] = m_local[i] - velocity * (most / speed);
        }
    }
    m_dirtyViolation = false;
    m_gravityStalls = 0;
    ++m_revision;
    const int iterations = result.iterations;
    result = engine.measuredValid && !tails ? engine.measured : measureViolation();
    result.iterations = iterations;
    if (!m_colliders.empty()) applyCollisions(result, -1, Vec3::Zero()); // hose_contact.cpp
    double stepMotion = 0.0;
    for (size_t i = 0; i < n; ++i) {
        result.movedPoints += m_local[i] != start[i] ? 1 : 0;
        stepMotion = std::max(stepMotion, (m_local[i] - start[i]).squaredNorm());
    }
    result.iterations = std::max(result.iterations, 1);
    // At rest: nothing moved more than kSettledMotion, or the hose has not come lower by kHover
    // for kStallSteps steps while staying near its lowest (a cycle of the projection near its
    // limits, or a creep of micrometres a step: it stops where it is).
    if (inputChanged) {
        m_gravityLowestEnergy = std::numeric_limits<double>::infinity();
        m_gravityStallSeconds = 0.0;
    }
    double energy = 0.0, totalMass = 0.0;
    const Vec3 down = m_spec.gravity.direction.normalized();
    for (size_t i = 0; i < n; ++i) {
        const double mass =
            0.5 * ((i > 0 ? m_restLength[i - 1] : 0.0) + (i + 1 < n ? m_restLength[i] : 0.0));
        energy -= mass * down.dot(m_local[i]);
        totalMass += mass;
    }
    if (energy < m_gravityLowestEnergy - kHover * engine.meanRest * totalMass) {
        m_gravityLowestEnergy = energy;
        m_gravityStallSeconds = 0.0;
    } else {
        m_gravityStallSeconds += seconds;
    }
    // A step cut short by the budget is not taken for rest by its small motion (the budget may
    // have made it small), only by not coming lower for kStallSeconds.
    const bool stalled = m_gravityStallSeconds >= kStallSeconds * (1.0 - 1e-9) &&
                         energy <= m_gravityLowestEnergy + kHover * engine.meanRest * totalMass;
    m_pendingFall = result.pending = scope.cut() && !stalled;
    if (stalled ||
        (!scope.cut() && std::sqrt(stepMotion) <= kSettledMotion * engine.meanRest *
                                                      (seconds / Gravity::kFrameSeconds))) {
        m_settledRevision = m_revision;
        m_gravityPrevious = m_local; // at rest: no velocity left
    }
    m_gravityLast = m_local;
    m_gravityStepSeconds = seconds;
    m_gravityInputRevision = m_revision;
    return result;
}

} // namespace chaintube
