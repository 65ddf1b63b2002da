// Gravity sag: quasi-static settling of the free points (an extension beyond the paper).
#include "chaintube/hose.h"

#include <algorithm>
#include <cmath>

namespace chaintube {

namespace {
constexpr double kDamping = 0.9;
constexpr int kNewtonSteps = 4;
constexpr double kProjectionTolerance = 1e-9;
} // namespace

/// The damped rounds behind Hose::sag() and Hose::step(): a small gravity step, then the
/// constraint projection. Points with inverse mass 0 (fixed, held) never move.
class SagRounds
{
public:
    SagRounds(Hose& hose, const Vec3& direction, int held)
        : h(hose), n(hose.m_local.size()), inverseMass(n, 0.0), minChord(n, 0.0), sub(n), diag(n), super(n),
          rhs(n), lambda(n), target(n), gradient(n)
    {
        meanRest = h.restLengthTotal() / static_cast<double>(n - 1);
        // Inverse masses: each point carries half of its adjacent rest lengths.
        for (size_t i = 0; i < n; ++i) {
            if (h.m_fixed[i] || static_cast<int>(i) == held) continue;
            const double mass =
                0.5 * ((i > 0 ? h.m_restLength[i - 1] : 0.0) + (i + 1 < n ? h.m_restLength[i] : 0.0));
            inverseMass[i] = 1.0 / mass;
        }
        // Bend limit as a lower bound on the neighbours' distance (law of cosines at rest lengths).
        for (size_t j = 1; j + 1 < n; ++j) {
            const double e = h.m_spec.material.expansionCoefficient;
            const double a = h.m_restLength[j - 1] * (1.0 - e), b = h.m_restLength[j] * (1.0 - e);
            // No limit (θ = π) means no constraint: |a − b| would otherwise pin unequal segments.
            minChord[j] = h.m_cosLimit[j] <= -1.0 + 1e-12
                              ? 0.0
                              : std::sqrt(std::max(0.0, a * a + b * b + 2.0 * a * b * h.m_cosLimit[j]));
        }
        bendLimited = std::any_of(minChord.begin(), minChord.end(), [](double c) { return c > 0.0; });
        step = direction.normalized() * (0.01 * meanRest);
    }

    /// One round: Verlet step against `previous` (updated), then the constraints. Gauss–Seidel
    /// (bend-limited hoses) runs at most maxSweeps sweeps.
    void round(std::vector<Vec3>& previous, int maxSweeps)
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
        // Restore the constraints (bounded): the length band by the direct projection, the
        // bend limits by Gauss–Seidel on the neighbours' distance. An under-converged
        // projection acts as a soft spring and lets the chain stretch under load: Gauss–Seidel
        // alone, 500 sweeps a round, left the 1.05 m catenary 0.3 % too deep after 0.35 s; the
        // direct projection gives +0.05 % in about 50 ms. With bend limits the two constraint
        // sets conflict and alternating the direct projection with Gauss–Seidel on the bends
        // did not converge; there Gauss–Seidel runs on both (slower, but it settles).
        if (!bendLimited) {
            projectLengths(kNewtonSteps);
            return;
        }
        for (int sweep = 0; sweep < maxSweeps; ++sweep) {
            double worst = 0.0;
            for (size_t s = 0; s + 1 < n; ++s)
                worst = std::max(worst, project(s, s + 1, h.m_minLength[s], h.m_maxLength[s]) / h.m_restLength[s]);
            for (size_t j = 1; j + 1 < n; ++j)
                worst = std::max(worst, project(j - 1, j + 1, minChord[j], 1e300) / meanRest);
            if (worst <= kProjectionTolerance) break;
        }
    }

    double meanRest = 0.0;

private:
    // Mass-weighted projection of lower ≤ |p_k − p_i| ≤ upper; returns the violation it removed.
    double project(size_t i, size_t k, double lower, double upper)
    {
        std::vector<Vec3>& p = h.m_local;
        const double wi = inverseMass[i], wk = inverseMass[k];
        if (wi + wk == 0.0) return 0.0;
        const Vec3 d = p[k] - p[i];
        const double length = d.norm();
        if (!(length > 0.0)) return 0.0;
        const double clamped = std::clamp(length, lower, upper);
        if (clamped == length) return 0.0;
        const Vec3 correction = d * ((length - clamped) / (length * (wi + wk)));
        p[i] += wi * correction;
        p[k] -= wk * correction;
        return std::abs(length - clamped);
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
            // Thomas algorithm: T λ = C.
            for (size_t k = 1; k < segments; ++k) {
                const double factor = sub[k] / diag[k - 1];
                diag[k] -= factor * super[k - 1];
                rhs[k] -= factor * rhs[k - 1];
            }
            lambda[segments - 1] = rhs[segments - 1] / diag[segments - 1];
            for (size_t k = segments - 1; k-- > 0;) lambda[k] = (rhs[k] - super[k] * lambda[k + 1]) / diag[k];
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
    std::vector<double> inverseMass, minChord;
    bool bendLimited = false;
    Vec3 step = Vec3::Zero();
    std::vector<double> sub, diag, super, rhs, lambda, target;
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
    constexpr int kMaxSweepsPerRound = 500;
    std::vector<Vec3> previous = m_local, twoBack = m_local;
    for (result.rounds = 0; result.rounds < options.maxRounds; ++result.rounds) {
        rounds.round(previous, kMaxSweepsPerRound);
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
    // Exact finish: the ChainTube propagation from the fixed points.
    result.update = settle();
    return result;
}

void Hose::releaseGrab()
{
    if (m_held < 0) return;
    m_held = -1;
    m_settledRevision = 0; // step(): the released point may fall
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
    constexpr int kMaxSweepsPerStepRound = 16;
    constexpr double kSettledMotion = 1e-6; // of the mean rest length, in the last round
    SagRounds engine(*this, m_spec.gravity.direction, m_held);
    const std::vector<Vec3> start = m_local;
    // Settled when the last round moved nothing against the state two rounds back (as in
    // sag(): the exact projection can leave a tiny two-round flip-flop of single points).
    if (m_gravityTwoBack.size() != n) m_gravityTwoBack = m_local;
    double moved = 0.0;
    for (int r = 0; r < rounds; ++r) {
        engine.round(m_gravityPrevious, kMaxSweepsPerStepRound);
        moved = 0.0;
        for (size_t i = 0; i < n; ++i) moved = std::max(moved, (m_local[i] - m_gravityTwoBack[i]).squaredNorm());
        m_gravityTwoBack = m_gravityPrevious; // the state before this round
    }
    // Exact pass from the fixed points and the held point.
    result = settleFrom(m_held);
    if (!m_colliders.empty()) applyCollisions(result, -1, Vec3::Zero()); // collision.cpp
    result.movedPoints = 0;
    for (size_t i = 0; i < n; ++i) result.movedPoints += m_local[i] != start[i] ? 1 : 0;
    if (std::sqrt(moved) <= kSettledMotion * engine.meanRest) {
        m_settledRevision = m_revision;
        m_gravityPrevious = m_local; // at rest: no velocity left
    }
    m_gravityLast = m_local;
    return result;
}

} // namespace chaintube
