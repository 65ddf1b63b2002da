// Gravity sag: quasi-static settling of the free points (an extension beyond the paper).
#include "chaintube/hose.h"

#include "banded_ldlt.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace chaintube {

namespace {
constexpr double kDamping = 0.9;
constexpr int kNewtonSteps = 4;
constexpr double kUnlimited = 1e300; // SagRounds::limitAngle of a joint without a bend limit
} // namespace

/// The damped rounds behind Hose::sag() and Hose::step(): a small gravity step, then the
/// constraint projection. Points with inverse mass 0 (fixed, held) never move.
class SagRounds
{
public:
    SagRounds(Hose& hose, const Vec3& direction, int held)
        : h(hose), n(hose.m_local.size()), inverseMass(n, 0.0), limitAngle(n, kUnlimited), sub(n), diag(n),
          super(n), rhs(n), lambda(n), target(n), gradient(n)
    {
        meanRest = h.restLengthTotal() / static_cast<double>(n - 1);
        // Inverse masses: each point carries half of its adjacent rest lengths.
        for (size_t i = 0; i < n; ++i) {
            if (h.m_fixed[i] || static_cast<int>(i) == held) continue;
            const double mass =
                0.5 * ((i > 0 ? h.m_restLength[i - 1] : 0.0) + (i + 1 < n ? h.m_restLength[i] : 0.0));
            inverseMass[i] = 1.0 / mass;
        }
        // Joints with a bend limit below π take part in the joint projection.
        for (size_t j = 1; j + 1 < n; ++j) {
            if (h.m_cosLimit[j] <= -1.0 + 1e-12) continue; // unlimited
            limitAngle[j] = std::atan2(h.m_sinLimit[j], h.m_cosLimit[j]);
            bendLimited = true;
        }
        step = direction.normalized() * (0.01 * meanRest);
    }

    /// One round: Verlet step against `previous` (updated), then the constraints (bend-limited
    /// hoses: at most maxNewtonSteps steps of the joint projection).
    void round(std::vector<Vec3>& previous, int maxNewtonSteps)
    {
        std::vector<Vec3>& p = h.m_local;
        for (size_t i = 0; i < n; ++i) {
            if (inverseMass[i] == 0.0) {
                previous[i] = p[i];
                continue;
            }
            const Vec3 velocity = p[i] - previous[i];
            previous[i] = p[i];
            p[i] += kDamping * velocity + step;
        }
        // Restore the constraints: without bend limits the length band by the direct
        // tridiagonal projection (an under-converged projection acts as a soft spring and lets
        // the chain stretch under load: Gauss–Seidel alone, 500 sweeps a round, left the 1.05 m
        // catenary 0.3 % too deep; the direct projection gives +0.05 %). With bend limits the
        // two sets conflict (Gauss–Seidel on both, or alternating the direct length projection
        // with bend sweeps, never converged, and the exact ChainTube pass from the fixed side
        // then undid the sag every step): lengths and bends are projected jointly, one banded
        // Newton system (see projectJointly).
        const bool touching = gatherContacts(previous);
        if (!bendLimited && !touching) {
            projectLengths(kNewtonSteps);
            return;
        }
        entryWorst = 0.0;
        const double left = projectJointly(maxNewtonSteps);
        bool finite = true;
        for (size_t i = 0; i < n && finite; ++i) finite = p[i].allFinite();
        if (!finite || !(left <= std::max(2.0 * entryWorst, 1e-6))) {
            // Diverged (a shape far from valid, e.g. a route that already breaks the bend
            // limits): the round is undone and leaves no velocity; finish() decides.
            for (size_t i = 0; i < n; ++i)
                if (inverseMass[i] != 0.0) p[i] = previous[i];
            ++failedRounds;
            return;
        }
        // A contact is inelastic and sticks (no sliding on while it holds): a point touching
        // its plane after the projection keeps no velocity. Without this a hose lying on a
        // floor slid on frictionlessly, pulled by the part hanging off the edge, for hundreds
        // of frames.
        for (size_t i = 0; touching && i < n; ++i)
            if (hasContact[i] && contactNormal[i].dot(p[i] - contactPoint[i]) - radius <= 1e-9 * meanRest)
                previous[i] = p[i];
    }

    /// Contacts inside the rounds (Hose::setColliders): each free point within reach of a
    /// collider gets the tangent plane at its closest point on the mesh (normal towards the
    /// point, or for a centre on the surface towards where it was) for the projection to keep
    /// it `radius` above. Returns whether any point has a contact. Planes are taken at the
    /// predicted positions, once per round; applyCollisions after the step still sweeps every
    /// move and checks the segments (sharp edges).
    bool gatherContacts(const std::vector<Vec3>& previous)
    {
        if (h.m_colliders.empty()) return false;
        const std::vector<Vec3>& p = h.m_local;
        // The contact keeps a skin of a tenth of the collision tolerance: applyCollisions then
        // sweeps each move from a resting position that does not touch (a point held exactly
        // at the radius was stopped by its sweep on rounding noise, and its contact rounds left
        // the band and bend limits off by up to 1e-6 instead of 1e-9).
        radius = h.outerRadius() + 0.1 * h.m_collisionOptions.tolerance;
        const double reach = radius + h.m_collisionOptions.tolerance + meanRest;
        Aabb box;
        for (const Vec3& point : p) box.extend(point + h.m_origin);
        box.min.array() -= reach;
        box.max.array() += reach;
        hasContact.assign(n, 0);
        contactNormal.assign(n, Vec3::Zero());
        contactPoint.assign(n, Vec3::Zero());
        bool any = false;
        for (const auto& collider : h.m_colliders) {
            const Aabb bounds = collider->worldBounds();
            if ((bounds.min.array() > box.max.array()).any() || (bounds.max.array() < box.min.array()).any()) continue;
            for (size_t i = 0; i < n; ++i) {
                if (inverseMass[i] == 0.0) continue;
                const double within = hasContact[i] ? (contactNormal[i].dot(p[i] - contactPoint[i])) : reach;
                const MeshCollider::Closest c = collider->closestToPoint(p[i] + h.m_origin, within);
                if (!c.found) continue;
                Vec3 normal = c.normal;
                const Vec3 onMesh = c.onMesh - h.m_origin;
                if (c.distance < 1e-12 * meanRest && normal.dot(previous[i] - onMesh) < 0.0) normal = -normal;
                if (!normal.allFinite()) continue;
                hasContact[i] = 1;
                contactNormal[i] = normal;
                contactPoint[i] = onMesh;
                any = true;
            }
        }
        return any;
    }

    /// The end of sag() and step(): when the rounds left every constraint within
    /// Hose::measureViolation()'s 1e-9 (after up to `extraSteps` more projection steps), their
    /// state is the answer. The exact ChainTube pass from the fixed points (settleFrom) is only
    /// the fallback: run on a shape the rounds already made valid it re-propagates from the
    /// fixed side and, between two clamps, would undo the sag every step.
    /// With `exactFallback` false (step(), whose state before is valid), a result the rounds
    /// could not make valid is undone instead (roundsFailed is set): the exact pass from the
    /// fixed points turns every joint over its limit about the fixed side, and near a steep
    /// attachment those turns add up to swings of 10 cm or more at a free end in one frame.
    UpdateResult finish(int held, int extraSteps, const std::vector<Vec3>& before, bool exactFallback = true)
    {
        for (const Vec3& point : h.m_local)
            if (!point.allFinite()) {
                h.m_local = before; // never reached (the rounds keep finite states); kept as a guard
                break;
            }
        UpdateResult result = h.measureViolation();
        if (result.status != Status::Ok) {
            if (bendLimited || !contactNormal.empty()) projectJointly(extraSteps);
            else projectLengths(extraSteps);
            result = h.measureViolation();
        }
        if (result.status != Status::Ok && !exactFallback) {
            const std::vector<Vec3> after = h.m_local;
            h.m_local = before;
            const UpdateResult previous = h.measureViolation();
            if (previous.status == Status::Ok) {
                h.m_dirtyViolation = false;
                roundsFailed = true;
                return previous; // nothing changed: the revision stays
            }
            h.m_local = after;
        }
        if (result.status != Status::Ok) {
            // The exact pass can itself fail on such a shape (a 21-point hose of the test-rig
            // sample between two clamps came out of it 5x overstretched): then the step is
            // undone when the state before it was valid.
            const UpdateResult exact = h.settleFrom(held);
            if (exact.status == Status::Ok) return exact;
            const std::vector<Vec3> after = h.m_local;
            h.m_local = before;
            const UpdateResult previous = h.measureViolation();
            if (previous.status != Status::Ok) {
                h.m_local = after;
                return exact;
            }
            h.m_dirtyViolation = false;
            return previous; // nothing changed: the revision stays
        }
        h.m_dirtyViolation = false;
        ++h.m_revision;
        return result;
    }

    double meanRest = 0.0;
    int failedRounds = 0; ///< rounds undone because the projection diverged
    bool roundsFailed = false; ///< finish() undid the rounds (exactFallback false)
    /// Scales the gravity step of each round (a retry with smaller moves).
    void scaleStep(double factor) { step *= factor; }

private:
    // Joint projection of the length band, the bend limits and the contacts: the mass-weighted
    // closest point to the predicted positions y (the state on entry) that satisfies all of
    // them, by sequential quadratic programming. Three constraints per point i: 3i the contact
    // of point i with its plane (n·(p_i − c) ≥ radius), 3i + 1 the turn φ_i at joint i
    // (φ_i ≤ limit), 3i + 2 the length of segment i (inside its band). Each Newton step solves
    //   (J M⁻¹ Jᵀ) λ = −C − J (y − x),   x ← y + M⁻¹ Jᵀ λ
    // for the active set; a constraint touches at most three consecutive points, so the matrix
    // is banded (half-bandwidth 6) and a banded LDLᵀ solves it in O(n). Active: violated, an
    // equality (a band of width 0), or active in the last step with a multiplier of the right
    // sign (a constraint held at its bound whose multiplier would pull, not push, is
    // released). With "violated only" and each step the smallest move from the last iterate
    // (the plain fast projection) the result was a feasible point but not the closest one, and
    // the damped rounds never came to rest (a 40-point bend-limited hose between two clamps
    // kept moving 1–5 mm per step, with no inertia at all too). Known limit: the iteration
    // leaves out the constraints' curvature, and under high tension (near the pinned ends of
    // a long hanging hose) it can end its steps oscillating by ~1e-4 m; step() then settles by
    // its frame-to-frame test. Returns the largest violation left (relative length, radians,
    // contact depth relative to the mean rest length).
    double projectJointly(int newtonSteps)
    {
        std::vector<Vec3>& p = h.m_local;
        const size_t m = 3 * n;
        band.assign(m * kBand, 0.0);
        value.assign(m, 0.0);
        multiplier.assign(m, 0.0);
        predicted.assign(p.begin(), p.end());
        jointGradient.assign(3 * m, Vec3::Zero());
        activeRow.assign(m, 0);
        boundSide.assign(m, 0);
        double worst = 0.0;
        double bestWorst = std::numeric_limits<double>::infinity();
        auto firstPoint = [](size_t c) { return c % 3 == 1 ? c / 3 - 1 : c / 3; };
        auto blocks = [](size_t c) { return c % 3 == 0 ? 1 : (c % 3 == 1 ? 3 : 2); };
        // The last pass only measures: the violation returned is the final state's.
        for (int it = 0; it <= newtonSteps; ++it) {
            worst = 0.0;
            double largestStep = 0.0;
            // Keeps c active when it is violated (`violation` > 0) or was held at its bound
            // with a multiplier of the right sign; side: +1 for g ≤ 0, −1 for g ≥ 0, 0 equality.
            auto decide = [&](size_t c, double violation, int side) {
                const bool held = activeRow[c] && boundSide[c] == side &&
                                  (side == 0 || (side > 0 ? multiplier[c] <= 0.0 : multiplier[c] >= 0.0));
                activeRow[c] = (violation > 0.0 || held || side == 0) ? 1 : 0;
                boundSide[c] = static_cast<signed char>(side);
                return activeRow[c] != 0;
            };
            for (size_t k = 0; k + 1 < n; ++k) {
                const size_t c = 3 * k + 2;
                const Vec3 d = p[k + 1] - p[k];
                const double length = d.norm();
                const double lo = h.m_minLength[k], hi = h.m_maxLength[k];
                const double excess = std::max(length - hi, lo - length);
                worst = std::max(worst, excess / h.m_restLength[k]);
                const int side = lo == hi ? 0 : (length - lo < hi - length ? -1 : +1);
                if (!(length > 0.0) || inverseMass[k] + inverseMass[k + 1] == 0.0 || !decide(c, excess, side)) {
                    activeRow[c] = 0;
                    continue;
                }
                const Vec3 unit = d / length;
                value[c] = length - (side < 0 ? lo : hi);
                jointGradient[3 * c] = -unit;
                jointGradient[3 * c + 1] = unit;
            }
            for (size_t j = 1; j + 1 < n; ++j) {
                if (!(limitAngle[j] < kUnlimited)) continue;
                const size_t c = 3 * j + 1;
                const Vec3 u = p[j] - p[j - 1], v = p[j + 1] - p[j];
                const double lu = u.norm(), lv = v.norm();
                const double sine = u.cross(v).norm(), cosine = u.dot(v);
                const double turn = std::atan2(sine, cosine);
                worst = std::max(worst, turn - limitAngle[j]);
                const double sinTurn = sine / (lu * lv);
                // A fold (φ near π) or a straight joint has no usable gradient: a fold is left to
                // the length rows and the next step (or the exact pass); straight is far inside.
                if (!(sinTurn > 1e-6) || inverseMass[j - 1] + inverseMass[j] + inverseMass[j + 1] == 0.0 ||
                    !decide(c, turn - limitAngle[j], +1)) {
                    activeRow[c] = 0;
                    continue;
                }
                const Vec3 uh = u / lu, vh = v / lv;
                const double c0 = uh.dot(vh);
                const Vec3 dPhiDu = -(vh - c0 * uh) / (lu * sinTurn);
                const Vec3 dPhiDv = -(uh - c0 * vh) / (lv * sinTurn);
                value[c] = turn - limitAngle[j];
                jointGradient[3 * c] = -dPhiDu;
                jointGradient[3 * c + 1] = dPhiDu - dPhiDv;
                jointGradient[3 * c + 2] = dPhiDv;
            }
            for (size_t i = 0; i < n && !contactNormal.empty(); ++i) {
                const size_t c = 3 * i;
                if (!hasContact[i] || inverseMass[i] == 0.0) continue;
                const double gap = contactNormal[i].dot(p[i] - contactPoint[i]) - radius;
                worst = std::max(worst, -gap / meanRest);
                if (!decide(c, -gap, -1)) continue;
                value[c] = gap;
                jointGradient[3 * c] = contactNormal[i];
            }
            // The iteration leaves out the constraints' curvature and can drift away again
            // from a nearly valid state (under high tension): the best state it met is kept.
            if (worst < bestWorst) {
                bestWorst = worst;
                best.assign(p.begin(), p.end());
            }
            if ((worst <= 1e-12 && it > 0 && lastStep <= 1e-12 * meanRest) || it == newtonSteps) break;
            // Assemble the band: A(a, a + d) for d = 0 … 6, summed over the points both touch.
            std::fill(band.begin(), band.end(), 0.0);
            for (size_t i = 0; i < n; ++i) {
                if (inverseMass[i] == 0.0) continue;
                // Rows touching point i: 3i − 2 (turn at i − 1) … 3i + 4 (turn at i + 1).
                size_t touching[7];
                Vec3 grad[7];
                int count = 0;
                const long centre = 3 * static_cast<long>(i);
                for (long c = centre - 2; c <= centre + 4; ++c) {
                    if (c < 0 || c >= static_cast<long>(m) || !activeRow[static_cast<size_t>(c)]) continue;
                    const size_t row = static_cast<size_t>(c);
                    const size_t first = firstPoint(row);
                    if (i < first || i >= first + static_cast<size_t>(blocks(row))) continue;
                    touching[count] = row;
                    grad[count] = jointGradient[3 * row + (i - first)];
                    ++count;
                }
                for (int x = 0; x < count; ++x)
                    for (int y = x; y < count; ++y)
                        band[touching[x] * kBand + (touching[y] - touching[x])] +=
                            inverseMass[i] * grad[x].dot(grad[y]);
            }
            // Right-hand side −C; inactive rows are identity rows with λ = 0.
            for (size_t c = 0; c < m; ++c) {
                if (!activeRow[c]) {
                    band[c * kBand] = 1.0;
                    multiplier[c] = 0.0;
                    continue;
                }
                double rhsValue = -value[c];
                const size_t first = firstPoint(c);
                for (int b = 0; b < blocks(c); ++b)
                    rhsValue -= jointGradient[3 * c + static_cast<size_t>(b)].dot(predicted[first + static_cast<size_t>(b)] -
                                                                                p[first + static_cast<size_t>(b)]);
                multiplier[c] = rhsValue;
            }
            // Banded LDLᵀ (no pivoting: the matrix is symmetric positive semi-definite); a pivot
            // that vanishes (dependent constraints) drops its constraint for this step.
            detail::solveBandedLdlt(band.data(), multiplier.data(), m, kBand);
            // x ← x + M⁻¹ Jᵀ Δλ; the multipliers add up over the steps (for the sign test).
            scratch.assign(predicted.begin(), predicted.end());
            for (size_t c = 0; c < m; ++c) {
                if (!activeRow[c] || multiplier[c] == 0.0) continue;
                const size_t first = firstPoint(c);
                for (int b = 0; b < blocks(c); ++b) {
                    const size_t i = first + static_cast<size_t>(b);
                    if (inverseMass[i] == 0.0) continue;
                    scratch[i] += (inverseMass[i] * multiplier[c]) * jointGradient[3 * c + static_cast<size_t>(b)];
                }
            }
            // Damped Newton: no point moves more than a quarter of the mean rest length per
            // step (a round starts within a gravity step of a valid state, so this only acts
            // on shapes far from valid, where the full step overshot and diverged).
            for (size_t i = 0; i < n; ++i) {
                if (inverseMass[i] == 0.0) continue;
                const double step2 = (scratch[i] - p[i]).squaredNorm();
                largestStep = std::max(largestStep, std::isfinite(step2) ? step2 : kUnlimited);
            }
            const double limit = 0.25 * meanRest;
            const double fullStep = std::sqrt(largestStep);
            const double fraction = largestStep > limit * limit ? limit / fullStep : 1.0;
            for (size_t i = 0; i < n; ++i) {
                if (inverseMass[i] == 0.0) continue;
                const Vec3 next = p[i] + fraction * (scratch[i] - p[i]);
                if (next.allFinite()) p[i] = next;
            }
            lastStep = fraction * std::sqrt(largestStep);
            if (it == 0) entryWorst = worst;
        }
        if (worst > bestWorst) {
            p.assign(best.begin(), best.end());
            worst = bestWorst;
        }
        return worst;
    }

    // Direct projection of the length band (Goldenthal et al. 2007, "fast projection"): the
    // constraints of a chain couple only neighbouring segments, so each Newton step of the
    // mass-weighted projection solves a tridiagonal system (Thomas algorithm, O(n)). Segments
    // inside their band are inactive (λ = 0). Returns the largest relative violation left.
    double projectLengths(int newtonSteps)
    {
        std::vector<Vec3>& p = h.m_local;
        const size_t segments = n - 1;
        double worst = 0.0;
        for (int it = 0; it < newtonSteps; ++it) {
            worst = 0.0;
            for (size_t k = 0; k < segments; ++k) {
                const Vec3 d = p[k + 1] - p[k];
                const double length = d.norm();
                target[k] = std::clamp(length, h.m_minLength[k], h.m_maxLength[k]);
                gradient[k] = 2.0 * d;
                rhs[k] = d.squaredNorm() - target[k] * target[k]; // C_k = |d|² − L²
                worst = std::max(worst, std::abs(length - target[k]) / h.m_restLength[k]);
            }
            if (worst <= 1e-13) break;
            for (size_t k = 0; k < segments; ++k) {
                const bool active = rhs[k] != 0.0 && inverseMass[k] + inverseMass[k + 1] > 0.0;
                diag[k] = active ? (inverseMass[k] + inverseMass[k + 1]) * gradient[k].squaredNorm() : 1.0;
                if (!active) rhs[k] = 0.0;
                sub[k] = super[k] = 0.0;
            }
            for (size_t k = 0; k + 1 < segments; ++k) {
                if (rhs[k] == 0.0 || rhs[k + 1] == 0.0) continue;
                const double coupling = -inverseMass[k + 1] * gradient[k].dot(gradient[k + 1]);
                super[k] = coupling;
                sub[k + 1] = coupling;
            }
            // Thomas algorithm: T λ = C. The forward pass keeps 1/diag (diag holds it
            // afterwards), so the back substitution multiplies: its chain has no division.
            diag[0] = 1.0 / diag[0];
            for (size_t k = 1; k < segments; ++k) {
                const double factor = sub[k] * diag[k - 1];
                diag[k] = 1.0 / (diag[k] - factor * super[k - 1]);
                rhs[k] -= factor * rhs[k - 1];
            }
            lambda[segments - 1] = rhs[segments - 1] * diag[segments - 1];
            for (size_t k = segments - 1; k-- > 0;) lambda[k] = (rhs[k] - super[k] * lambda[k + 1]) * diag[k];
            // Δx = −M⁻¹ Jᵀ λ, with ∂C_k/∂x_k = −g_k and ∂C_k/∂x_{k+1} = +g_k.
            for (size_t i = 0; i < n; ++i) {
                if (inverseMass[i] == 0.0) continue;
                Vec3 force = Vec3::Zero();
                if (i < segments) force -= gradient[i] * lambda[i];
                if (i > 0) force += gradient[i - 1] * lambda[i - 1];
                p[i] -= inverseMass[i] * force;
            }
        }
        return worst;
    }

    Hose& h;
    size_t n;
    std::vector<double> inverseMass;
    std::vector<double> limitAngle; ///< per joint, radians; kUnlimited where there is none
    bool bendLimited = false;
    Vec3 step = Vec3::Zero();
    std::vector<double> sub, diag, super, rhs, lambda, target;
    static constexpr size_t kBand = 7; // half-bandwidth 6 plus the diagonal
    std::vector<double> band, value, multiplier;
    std::vector<Vec3> jointGradient, scratch, predicted, best; // best: projectJointly's best state met
    std::vector<unsigned char> activeRow;
    std::vector<signed char> boundSide;
    double lastStep = 0.0;
    double entryWorst = 0.0; ///< projectJointly: violation of the predicted positions
    // Contacts (colliders): per point, the plane it must stay above for this round.
    double radius = 0.0;
    std::vector<unsigned char> hasContact;
    std::vector<Vec3> contactNormal, contactPoint;
    std::vector<Vec3> gradient;
};

SagResult Hose::sag(const SagOptions& options)
{
    SagResult result;
    const Vec3 direction = options.gravityDirection;
    const size_t n = m_local.size();
    const bool anyFixed = std::any_of(m_fixed.begin(), m_fixed.end(), [](unsigned char f) { return f != 0; });
    if (!direction.allFinite() || !(direction.norm() > 0.0) || !anyFixed || options.maxRounds < 0 ||
        !(options.tolerance > 0.0)) {
        result.update.status = Status::InvalidInput;
        return result;
    }
    SagRounds rounds(*this, direction, -1);
    const std::vector<Vec3> before = m_local;
    constexpr int kNewtonStepsPerRound = 50; // the joint projection stops at 1e-12 long before
    std::vector<Vec3> previous = m_local, twoBack = m_local;
    for (result.rounds = 0; result.rounds < options.maxRounds; ++result.rounds) {
        rounds.round(previous, kNewtonStepsPerRound);
        // Settled when the shape no longer changes over two rounds (a tiny two-round
        // flip-flop of single points has been seen with the exact projection; comparing with
        // the state two rounds back ignores it, and the exact pass below ends it).
        double moved = 0.0;
        for (size_t i = 0; i < n; ++i) moved = std::max(moved, (m_local[i] - twoBack[i]).squaredNorm());
        twoBack = previous;
        if (result.rounds > 1 && std::sqrt(moved) <= options.tolerance * rounds.meanRest) {
            result.settled = true;
            break;
        }
    }
    // The rounds' state when it holds every constraint, else the exact ChainTube pass.
    result.update = rounds.finish(-1, 4 * kNewtonStepsPerRound, before);
    return result;
}

void Hose::releaseGrab()
{
    if (m_held < 0) return;
    m_held = -1;
    m_settledRevision = 0; // step(): the released point may fall
}

void Hose::markSettled()
{
    m_gravityPrevious.clear();
    m_gravityLast.clear();
    m_gravityTwoBack.clear();
    m_gravityInputRevision = 0;
    m_gravityLowestEnergy = 0.0;
    m_gravityStallSteps = 0;
    m_gravityScale = 1.0;
    m_settledRevision = m_revision;
}

UpdateResult Hose::step(int rounds)
{
    UpdateResult result;
    if (!m_spec.gravity.enabled || m_settledRevision == m_revision || rounds <= 0) return result;
    const size_t n = m_local.size();
    const bool anyFixed = std::any_of(m_fixed.begin(), m_fixed.end(), [](unsigned char f) { return f != 0; });
    if (!anyFixed && m_held < 0) {
        m_settledRevision = m_revision; // nothing to hang from
        return result;
    }
    if (m_gravityPrevious.size() != n || m_gravityLast.size() != n) {
        m_gravityPrevious = m_local;
    } else {
        // Moves made since the last step (grabs, attachments) carry no velocity: shift the
        // previous positions with them, so a drag never flings the hose.
        for (size_t i = 0; i < n; ++i) {
            m_gravityPrevious[i] += m_local[i] - m_gravityLast[i];
            if (m_gravityTwoBack.size() == n) m_gravityTwoBack[i] += m_local[i] - m_gravityLast[i];
        }
    }
    const std::uint64_t inputRevision = m_revision; // what the last step left, unless an input changed
    constexpr int kNewtonStepsPerStepRound = 16; // each O(n); 2–4 are typical once falling slowly
    constexpr double kSettledMotion = 1e-6; // of the mean rest length, in the last round
    if (m_gravityInputRevision != inputRevision) m_gravityScale = 1.0; // an input changed
    SagRounds engine(*this, m_spec.gravity.direction, m_held);
    engine.scaleStep(m_gravityScale);
    const std::vector<Vec3> start = m_local;
    // Settled when the last round moved nothing against the state two rounds back (as in
    // sag(): the exact projection can leave a tiny two-round flip-flop of single points).
    if (m_gravityTwoBack.size() != n) m_gravityTwoBack = m_local;
    double moved = 0.0;
    for (int r = 0; r < rounds; ++r) {
        engine.round(m_gravityPrevious, kNewtonStepsPerStepRound);
        moved = 0.0;
        for (size_t i = 0; i < n; ++i) moved = std::max(moved, (m_local[i] - m_gravityTwoBack[i]).squaredNorm());
        m_gravityTwoBack = m_gravityPrevious; // the state before this round
    }
    // The rounds' state if it holds the constraints; else the step again from rest; else the
    // state before (the exact pass from the fixed points only when that was not valid either).
    result = engine.finish(m_held, 4 * kNewtonStepsPerStepRound, start, false);
    if (!engine.roundsFailed) {
        m_gravityScale = std::min(1.0, 1.25 * m_gravityScale);
    } else {
        // Once more from rest (the velocity carried in made the moves too large for the
        // projection), then from rest with a quarter and a sixteenth of the gravity step (near
        // its limits the projection may only manage small moves: a bend-limited tail off a
        // steep attachment otherwise stopped 5.6 cm above its static sag, see hose.h); if all
        // fail the hose stays where it was, without velocity.
        // The scale that worked is where the next step starts (growing by 1.25 a step while
        // steps succeed): a hose that needs small steps does not pay for failing ones each step.
        const double tried = m_gravityScale;
        for (const double scale : {tried, tried / 4, tried / 16}) {
            m_gravityPrevious = start;
            SagRounds fromRest(*this, m_spec.gravity.direction, m_held);
            fromRest.scaleStep(scale);
            for (int r = 0; r < rounds; ++r) fromRest.round(m_gravityPrevious, kNewtonStepsPerStepRound);
            result = fromRest.finish(m_held, 4 * kNewtonStepsPerStepRound, start, false);
            if (!fromRest.roundsFailed) {
                m_gravityScale = scale;
                break;
            }
            m_gravityPrevious = start;
        }
        m_gravityTwoBack = start;
        moved = 0.0;
        for (size_t i = 0; i < n; ++i) moved = std::max(moved, (m_local[i] - start[i]).squaredNorm());
    }
    if (!m_colliders.empty()) applyCollisions(result, -1, Vec3::Zero()); // collision.cpp
    result.movedPoints = 0;
    double stepMotion = 0.0;
    for (size_t i = 0; i < n; ++i) {
        result.movedPoints += m_local[i] != start[i] ? 1 : 0;
        stepMotion = std::max(stepMotion, (m_local[i] - start[i]).squaredNorm());
    }
    // Also settled when the frame did not change: the joint projection can end its rounds in
    // a cycle that returns to the same state every step (see projectJointly); nothing visible
    // moves, and from here on nothing does.
    // And settled when the potential energy has not come lower by kHover (1 % of a segment in
    // mean height) for kStallSteps steps while staying close to its low: a bend-limited tail
    // creeping down by micrometres a step after its fall (with the small retry steps) stops,
    // and so does a cycle of the joint projection that moves points every step without the
    // hose coming lower (seen near pinned ends under high tension with the bend limit binding:
    // 0.5-1.2 mm a step, the mean height varying by 4e-5 m). The damping takes any real swing
    // out long before (0.9 of the velocity a round); a hose still far above its lowest state
    // (e.g. rising while the exact pass untangles it) is not stopped.
    constexpr int kStallSteps = 120;
    constexpr double kHover = 0.01; // of the mean rest length, in mean height
    if (m_gravityInputRevision != inputRevision) { // an input changed: start over
        m_gravityLowestEnergy = std::numeric_limits<double>::infinity();
        m_gravityStallSteps = 0;
    }
    double energy = 0.0, totalMass = 0.0;
    const Vec3 down = m_spec.gravity.direction.normalized();
    for (size_t i = 0; i < n; ++i) {
        const double mass = 0.5 * ((i > 0 ? m_restLength[i - 1] : 0.0) + (i + 1 < n ? m_restLength[i] : 0.0));
        energy -= mass * down.dot(m_local[i]);
        totalMass += mass;
    }
    if (energy < m_gravityLowestEnergy - kHover * engine.meanRest * totalMass) {
        m_gravityLowestEnergy = energy;
        m_gravityStallSteps = 0;
    } else {
        ++m_gravityStallSteps;
    }
    if (std::sqrt(moved) <= kSettledMotion * engine.meanRest ||
        (rounds >= 2 && std::sqrt(stepMotion) <= kSettledMotion * engine.meanRest) ||
        (m_gravityStallSteps >= kStallSteps &&
         energy <= m_gravityLowestEnergy + kHover * engine.meanRest * totalMass)) {
        m_settledRevision = m_revision;
        m_gravityPrevious = m_local; // at rest: no velocity left
    }
    m_gravityLast = m_local;
    m_gravityInputRevision = m_revision;
    return result;
}

} // namespace chaintube
