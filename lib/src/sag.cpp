// Gravity sag: quasi-static settling of the free points (an extension beyond the paper).
#include "chaintube/hose.h"

#include <algorithm>
#include <cmath>

namespace chaintube {

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
    const double meanRest = restLengthTotal() / static_cast<double>(n - 1);
    // Inverse masses: each point carries half of its adjacent rest lengths.
    std::vector<double> inverseMass(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
        if (m_fixed[i]) continue;
        const double mass = 0.5 * ((i > 0 ? m_restLength[i - 1] : 0.0) + (i + 1 < n ? m_restLength[i] : 0.0));
        inverseMass[i] = 1.0 / mass;
    }
    // Bend limit as a lower bound on the neighbours' distance (law of cosines at rest lengths).
    std::vector<double> minChord(n, 0.0);
    for (size_t j = 1; j + 1 < n; ++j) {
        const double a = m_restLength[j - 1] * (1.0 - m_spec.material.expansionCoefficient);
        const double b = m_restLength[j] * (1.0 - m_spec.material.expansionCoefficient);
        minChord[j] = std::sqrt(std::max(0.0, a * a + b * b + 2.0 * a * b * m_cosLimit[j]));
    }
    // Mass-weighted projection of lower ≤ |p_k − p_i| ≤ upper; returns the violation it removed.
    auto project = [&](size_t i, size_t k, double lower, double upper) {
        const double wi = inverseMass[i], wk = inverseMass[k];
        if (wi + wk == 0.0) return 0.0;
        const Vec3 d = m_local[k] - m_local[i];
        const double length = d.norm();
        if (!(length > 0.0)) return 0.0;
        const double target = std::clamp(length, lower, upper);
        if (target == length) return 0.0;
        const Vec3 correction = d * ((length - target) / (length * (wi + wk)));
        m_local[i] += wi * correction;
        m_local[k] -= wk * correction;
        return std::abs(length - target);
    };

    // Damped Verlet steps of a fixed size small against the segments, each followed by
    // Gauss–Seidel sweeps of the constraints. The step size only sets the speed: at rest the
    // constraint forces balance gravity whatever it is.
    const Vec3 step = direction.normalized() * (0.01 * meanRest);
    constexpr double kDamping = 0.9;
    constexpr int kMaxSweepsPerRound = 500;
    constexpr double kProjectionTolerance = 1e-9;
    std::vector<Vec3> previous = m_local;
    for (result.rounds = 0; result.rounds < options.maxRounds; ++result.rounds) {
        for (size_t i = 0; i < n; ++i) {
            if (m_fixed[i]) continue;
            const Vec3 velocity = m_local[i] - previous[i];
            previous[i] = m_local[i];
            m_local[i] += kDamping * velocity + step;
        }
        // Sweep until the constraints hold again (bounded): an under-converged projection
        // behaves like a soft spring and lets the chain stretch under load (with 50 sweeps a
        // round the 1.05 m catenary sags 1.9 % too far, with 500 sweeps 0.3 %).
        for (int sweep = 0; sweep < kMaxSweepsPerRound; ++sweep) {
            double worst = 0.0;
            for (size_t s = 0; s + 1 < n; ++s) worst = std::max(worst, project(s, s + 1, m_minLength[s], m_maxLength[s]) / m_restLength[s]);
            for (size_t j = 1; j + 1 < n; ++j) worst = std::max(worst, project(j - 1, j + 1, minChord[j], 1e300) / meanRest);
            if (worst <= kProjectionTolerance) break;
        }
        double moved = 0.0;
        for (size_t i = 0; i < n; ++i) moved = std::max(moved, (m_local[i] - previous[i]).squaredNorm());
        if (std::sqrt(moved) <= options.tolerance * meanRest) {
            result.settled = true;
            break;
        }
    }
    // Exact finish: the ChainTube propagation from the fixed points.
    result.update = settle();
    return result;
}

} // namespace chaintube
