// SpanSolver::reach: a held point brought as near a target beyond reach as the span allows,
// by SQP steps in the span's own degrees of freedom, each closed again by the Newton solve.
#include "banded_ldlt.h"
#include "span_kinematics.h"
#include "span_solver.h"
#include "vector_set.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace chaintube::detail {

namespace {

/// SpanSolver::reach: active-set passes a step (each one factor of the band).
constexpr int kReachPasses = 4;
/// SpanSolver::reach: chord steps that close the span after a step, then Newton steps of
/// solve() at most (a step whose closing fails in fewer leaves more of the budget to the next).
constexpr int kReachChords = 2;
constexpr int kReachCloseSteps = 5;
/// SpanSolver::reach: the budget a step needs left to be tried.
constexpr int kReachCloseReserve = 3;

} // namespace

SpanSolver::Outcome SpanSolver::reach(int root, int end, const Vec3& endTarget,
                                      const std::vector<SpanGoal>& goals, int moving,
                                      const Vec3& target, const Vec3* rootDirection,
                                      const Vec3* endDirection, int maxIterations, double tolerance,
                                      double& metric)
{
    Outcome out;
    out.valid = true;
    std::vector<Vec3>& p = h.m_local;
    const int dir = end > root ? 1 : -1;
    const int m = (end - root) * dir; // segments
    const int goalCount = static_cast<int>(goals.size());
    if (m < 2 || moving < 0 || moving >= goalCount || goalCount > (kMaxRows - 4) / 3) return out;
    auto point = [&](int s) { return static_cast<size_t>(root + dir * s); };
    auto segment = [&](int s) { return static_cast<size_t>(dir > 0 ? root + s : root - s - 1); };
    const size_t segments = static_cast<size_t>(m);
    const bool stretchable = h.m_spec.material.expansionCoefficient > 0.0;
    const int nv = stretchable ? 3 : 2; // per segment: two turns across it (and its length)
    const size_t vars = segments * static_cast<size_t>(nv);
    const size_t width = 2 * static_cast<size_t>(nv); // block tridiagonal
    const double rest = h.m_restLength[segment(m - 1)];
    const int goalPoint = (goals[static_cast<size_t>(moving)].point - root) * dir;

    // Row blocks of three: the hard goals, the end (hard), the moving goal (soft, last).
    std::vector<SpanGoal> hardGoals;
    int blockPoint[kMaxRows / 3];
    Vec3 blockTarget[kMaxRows / 3];
    int blocks = 0;
    for (int g = 0; g < goalCount; ++g) {
        if (g == moving) continue;
        const SpanGoal& goal = goals[static_cast<size_t>(g)];
        hardGoals.push_back({goal.point, goal.target, true});
        blockPoint[blocks] = (goal.point - root) * dir;
        blockTarget[blocks++] = goal.target;
    }
    blockPoint[blocks] = m;
    blockTarget[blocks++] = endTarget;
    blockPoint[blocks] = goalPoint;
    blockTarget[blocks++] = target;
    const int rows = 3 * blocks, soft = blocks - 1;

    // Joint s (0 … m − 1) turns segment s against the one before it (or rootDirection); joint m
    // is the end's, against endDirection.
    auto jointLimited = [&](int s) {
        if (s == 0 && !rootDirection) return false;
        if (s == m && !endDirection) return false;
        return h.m_cosLimit[point(s)] > -1.0 + 1e-12;
    };
    // The coefficients of u·(θ_s − θ_{s−1}) (joint s's turn about u, θ the segments' turns)
    // over the variables of segments s − 1 and s; returns how many.
    auto jointRow = [&](int s, const Vec3& u, size_t index[4], double a[4]) {
        const size_t k = static_cast<size_t>(s);
        int count = 0;
        if (s > 0) {
            const size_t v = (k - 1) * static_cast<size_t>(nv);
            index[count] = v, a[count++] = -u.dot(m_reachFirst[k - 1]);
            index[count] = v + 1, a[count++] = -u.dot(m_reachSecond[k - 1]);
        }
        if (s < m) {
            const size_t v = k * static_cast<size_t>(nv);
            index[count] = v, a[count++] = u.dot(m_reachFirst[k]);
            index[count] = v + 1, a[count++] = u.dot(m_reachSecond[k]);
        }
        return count;
    };
    std::vector<Vec3>& d = m_reachDirection;
    std::vector<Vec3>& e1 = m_reachFirst;
    std::vector<Vec3>& e2 = m_reachSecond;
    std::vector<Vec3>& q = m_reachPositions;
    std::vector<double>& l = m_reachLength;
    d.resize(segments);
    e1.resize(segments);
    e2.resize(segments);
    q.resize(segments + 1);
    l.resize(segments);
    m_reachNormal.resize(segments + 1);
    m_reachRoom.resize(segments + 1);
    m_reachHeld.resize(segments + 1);
    m_band.resize(vars * width);
    m_columns.resize(static_cast<size_t>(rows) * vars);
    m_rhs.resize(vars);
    m_step.resize(vars);
    std::vector<double> lengthRoom(segments, 0.0);
    std::vector<unsigned char> lengthHeld(segments, 0);
    std::vector<double> bendMultiplier(segments + 1, 0.0);
    double lastKappa = 0.0;

    auto distance = [&]() { return (p[point(goalPoint)] - target).norm(); };
    double& sigma = metric;
    double mu[kMaxRows] = {}; // the hard rows' multipliers (Lagrangian + μ·c)
    double error = distance();
    std::vector<Vec3> saved;
    const int wantedIterations = maxIterations;
    maxIterations = h.budgetedSteps(maxIterations); // the update's budget (Hose::setBudget)
    while (out.iterations + kReachCloseReserve < maxIterations) {
        if (error <= tolerance * rest) {
            out.goalsMet = true;
            break;
        }
        ++out.iterations;
        h.spendSteps(1, 1, 1); // the closing solve() below spends its own
        // The state: positions, directions, lengths, a basis across each segment.
        for (int s = 0; s <= m; ++s)
            q[static_cast<size_t>(s)] = p[point(s)];
        for (size_t s = 0; s < segments; ++s) {
            const Vec3 v = q[s + 1] - q[s];
            l[s] = v.norm();
            d[s] = l[s] > 0.0 ? Vec3(v / l[s]) : (s > 0 ? d[s - 1] : Vec3::UnitX());
            e1[s] = anyPerpendicular(d[s]);
            e2[s] = d[s].cross(e1[s]);
        }
        // Each joint's bend normal and room to its limit; joints at their limit start held.
        for (int s = 0; s <= m; ++s) {
            const size_t k = static_cast<size_t>(s);
            m_reachHeld[k] = 0;
            m_reachNormal[k] = Vec3::Zero();
            m_reachRoom[k] = 0.0;
            if (!jointLimited(s)) continue;
            const Vec3& before = s == 0 ? *rootDirection : d[k - 1];
            const Vec3& after = s == m ? *endDirection : d[k];
            const Vec3 cross = before.cross(after);
            const double sn = cross.norm();
            const double limit = h.m_limitAngle[point(s)];
            m_reachRoom[k] = limit - std::atan2(sn, before.dot(after));
            if (sn > 1e-12) m_reachNormal[k] = cross / sn;
            if (sn > 1e-12 && m_reachRoom[k] <= 1e-9 * limit) m_reachHeld[k] = 1;
        }
        if (stretchable)
            for (size_t s = 0; s < segments; ++s) {
                const size_t k = segment(static_cast<int>(s));
                lengthHeld[s] = l[s] >= h.m_maxLength[k]   ? kHeldAtMax
                                : l[s] <= h.m_minLength[k] ? kHeldAtMin
                                                           : 0;
            }
        // The forces each segment carries: the multipliers of the rows beyond it, and the soft
        // goal's residual. A stretch under tension (F·d < 0) resists a sideways turn by
        // −l F·d (the curvature of the Lagrangian across the segment, whose along-part is 0).
        Vec3 residual[kMaxRows / 3];
        for (int b = 0; b < blocks; ++b)
            residual[b] = q[static_cast<size_t>(blockPoint[b])] - blockTarget[b];
        Vec3 force[kMaxRows / 3];
        for (int b = 0; b < blocks; ++b)
            force[b] = b == soft ? residual[b] : Vec3(mu[3 * b], mu[3 * b + 1], mu[3 * b + 2]);
        auto carried = [&](size_t s) {
            Vec3 f = Vec3::Zero();
            for (int b = 0; b < blocks; ++b)
                if (static_cast<size_t>(blockPoint[b]) > s) f += force[b];
            return f;
        };
        // The rows of C (the same in every pass): row (b, i) moves with segment s < its point
        // by θ × l d (turns e1, e2: −l e2, l e1) and by d with its length.
        for (int b = 0; b < blocks; ++b)
            for (int i = 0; i < 3; ++i) {
                double* column = m_columns.data() + static_cast<size_t>(3 * b + i) * vars;
                std::fill(column, column + vars, 0.0);
                for (int s = 0; s < blockPoint[b]; ++s) {
                    const size_t k = static_cast<size_t>(s);
                    double* c = column + k * static_cast<size_t>(nv);
                    c[0] = -l[k] * e2[k][i];
                    c[1] = l[k] * e1[k][i];
                    if (stretchable) c[2] = d[k][i];
                }
            }
        double x[kMaxRows];
        RowMatrix hardSchur; // S of the hard rows, for the chord steps
        bool solved = false;
        bool estimate = out.iterations == 1;
        for (int pass = 0; pass < kReachPasses && !solved; ++pass) {
            // The band: metric + curvature, then the held joints' and lengths' penalties.
            std::fill(m_band.begin(), m_band.end(), 0.0);
            std::fill(m_rhs.begin(), m_rhs.end(), 0.0);
            double largest = 0.0;
            for (size_t s = 0; s < segments; ++s) {
                const double curvature = std::max(0.0, -l[s] * carried(s).dot(d[s]));
                const double diagonal = sigma * rest * rest + curvature;
                const size_t v = s * static_cast<size_t>(nv);
                m_band[v * width] = m_band[(v + 1) * width] = diagonal;
                if (stretchable) m_band[(v + 2) * width] = sigma;
                largest = std::max({largest, diagonal, stretchable ? sigma : 0.0});
            }
            const double kappa = 1e6 * largest;
            lastKappa = kappa;
            for (int s = 0; s <= m; ++s) {
                const size_t k = static_cast<size_t>(s);
                if (!m_reachHeld[k]) continue;
                const Vec3& n = m_reachNormal[k];
                size_t index[4];
                double a[4];
                const int count = jointRow(s, n, index, a);
                for (int i = 0; i < count; ++i) {
                    for (int j = i; j < count; ++j)
                        m_band[index[i] * width + (index[j] - index[i])] += kappa * a[i] * a[j];
                    m_rhs[index[i]] += kappa * m_reachRoom[k] * a[i];
                }
            }
            // The cone of a joint on its limit curves: turning its segment out of the bend
            // plane (about c = n × d) by α grows the turn by α² / (2 tan φ), weighted by the
            // joint's multiplier from the last step.
            for (int s = 0; s <= m; ++s) {
                const size_t k = static_cast<size_t>(s);
                if (!(bendMultiplier[k] > 0.0) || m_reachNormal[k].squaredNorm() == 0.0) continue;
                const double turnNow = h.m_limitAngle[point(s)] - m_reachRoom[k];
                if (!(turnNow > 1e-9)) continue;
                const Vec3& after = s < m ? d[k] : *endDirection;
                const Vec3 c = m_reachNormal[k].cross(after).normalized();
                const double w = bendMultiplier[k] / std::tan(turnNow);
                size_t index[4];
                double a[4];
                const int count = jointRow(s, c, index, a);
                for (int i = 0; i < count; ++i)
                    for (int j = i; j < count; ++j)
                        m_band[index[i] * width + (index[j] - index[i])] += w * a[i] * a[j];
            }
            if (stretchable)
                for (size_t s = 0; s < segments; ++s) {
                    if (!lengthHeld[s]) continue;
                    const size_t v = s * static_cast<size_t>(nv) + 2,
                                 k = segment(static_cast<int>(s));
                    lengthRoom[s] =
                        (lengthHeld[s] == kHeldAtMax ? h.m_maxLength[k] : h.m_minLength[k]) - l[s];
                    m_band[v * width] += kappa;
                    m_rhs[v] += kappa * lengthRoom[s];
                }
            factorBandedLdlt(m_band.data(), vars, width);
            // S = C K⁻¹ Cᵀ (+ I on the soft rows), from the columns before and after the solve.
            RowMatrix schur;
            schur.setZero(rows, rows);
            m_step = m_rhs;
            solveFactoredBandedLdlt(m_band.data(), m_step.data(), vars, width); // K⁻¹ k
            // Row r of C times y (row r reaches the segments before its point only).
            auto rowTimes = [&](int r, const double* y) {
                const double* row = m_columns.data() + static_cast<size_t>(r) * vars;
                const size_t used =
                    static_cast<size_t>(blockPoint[r / 3]) * static_cast<size_t>(nv);
                double sum = 0.0;
                for (size_t v = 0; v < used; ++v)
                    sum += row[v] * y[v];
                return sum;
            };
            RowVector rhs(rows);
            for (int r = 0; r < rows; ++r)
                rhs(r) = residual[r / 3][r % 3] + rowTimes(r, m_step.data());
            // K⁻¹ Cᵀ for the step, column by column, and S from them.
            m_solved.resize(static_cast<size_t>(rows) * vars);
            for (int r = 0; r < rows; ++r) {
                const double* column = m_columns.data() + static_cast<size_t>(r) * vars;
                double* solvedColumn = m_solved.data() + static_cast<size_t>(r) * vars;
                std::copy(column, column + vars, solvedColumn);
                solveFactoredBandedLdlt(m_band.data(), solvedColumn, vars, width);
                for (int c = 0; c <= r; ++c)
                    schur(c, r) = rowTimes(c, solvedColumn);
            }
            if (estimate) {
                // The hard rows' first-order multipliers, ∇f + Cᵀμ = 0 in the least squares of
                // this metric: μ = −S_hh⁻¹ S_hg r_g (S_hg = C_h K⁻¹ C_gᵀ, ∇f = C_gᵀ r_g).
                const int hardRows = 3 * soft;
                RowVector rg = residual[soft];
                RowMatrix shh =
                    schur.topLeftCorner(hardRows, hardRows).selfadjointView<Eigen::Upper>();
                const RowVector estimateMu =
                    -shh.ldlt().solve(schur.block(0, hardRows, hardRows, 3) * rg);
                for (int r = 0; r < hardRows; ++r)
                    mu[r] = estimateMu(r);
                for (int b = 0; b < soft; ++b)
                    force[b] = Vec3(mu[3 * b], mu[3 * b + 1], mu[3 * b + 2]);
                estimate = false;
                --pass;
                continue;
            }
            hardSchur = schur.topLeftCorner(3 * soft, 3 * soft);
            for (int i = 0; i < 3; ++i)
                schur(3 * soft + i, 3 * soft + i) += 1.0;
            const double scale = schur.diagonal().cwiseAbs().maxCoeff() + 1e-300;
            double dense[kMaxRows * kMaxRows];
            for (int i = 0; i < rows; ++i)
                for (int j = i; j < rows; ++j)
                    dense[i * rows + (j - i)] = schur(i, j) + (i == j ? 1e-13 * scale : 0.0);
            for (int i = 0; i < rows; ++i)
                x[i] = rhs(i);
            solveDenseLdlt(dense, x, static_cast<size_t>(rows));
            // The step: K⁻¹ k − K⁻¹ Cᵀ μ.
            for (int r = 0; r < rows; ++r) {
                const double* column = m_solved.data() + static_cast<size_t>(r) * vars;
                for (size_t v = 0; v < vars; ++v)
                    m_step[v] -= column[v] * x[r];
            }
            // The active set: a held joint that the step turns back inside is freed, a free one
            // that it turns beyond its limit is held (and the lengths at their bands alike).
            bool changed = false;
            auto theta = [&](size_t s) {
                const size_t v = s * static_cast<size_t>(nv);
                return Vec3(m_step[v] * e1[s] + m_step[v + 1] * e2[s]);
            };
            for (int s = 0; s <= m; ++s) {
                const size_t k = static_cast<size_t>(s);
                if (!jointLimited(s)) continue;
                const Vec3 turn =
                    (s < m ? theta(k) : Vec3::Zero()) - (s > 0 ? theta(k - 1) : Vec3::Zero());
                const Vec3& n = m_reachNormal[k];
                if (m_reachHeld[k]) {
                    if (n.dot(turn) < m_reachRoom[k]) m_reachHeld[k] = 0, changed = true;
                } else if (n.squaredNorm() > 0.0) {
                    if (n.dot(turn) > m_reachRoom[k]) m_reachHeld[k] = 1, changed = true;
                } else {
                    const Vec3& axis = s < m ? d[k] : d[k - 1];
                    const Vec3 across = turn - axis.dot(turn) * axis;
                    if (across.norm() > m_reachRoom[k]) {
                        m_reachNormal[k] = across.normalized();
                        m_reachHeld[k] = 1;
                        changed = true;
                    }
                }
            }
            if (stretchable)
                for (size_t s = 0; s < segments; ++s) {
                    const double dl = m_step[s * static_cast<size_t>(nv) + 2];
                    const size_t k = segment(static_cast<int>(s));
                    if (lengthHeld[s]) {
                        if (lengthHeld[s] == kHeldAtMax ? dl < lengthRoom[s] : dl > lengthRoom[s])
                            lengthHeld[s] = 0, changed = true;
                    } else if (l[s] + dl > h.m_maxLength[k]) {
                        lengthHeld[s] = kHeldAtMax, changed = true;
                    } else if (l[s] + dl < h.m_minLength[k]) {
                        lengthHeld[s] = kHeldAtMin, changed = true;
                    }
                }
            solved = !changed;
        }
        for (int r = 0; r < 3 * soft; ++r)
            mu[r] = x[r];
        // The held joints' multipliers, for the next step's cone terms: their penalties' forces.
        for (int s = 0; s <= m; ++s) {
            const size_t k = static_cast<size_t>(s);
            bendMultiplier[k] = 0.0;
            if (!m_reachHeld[k]) continue;
            size_t index[4];
            double a[4];
            const int count = jointRow(s, m_reachNormal[k], index, a);
            double turn = 0.0;
            for (int i = 0; i < count; ++i)
                turn += a[i] * m_step[index[i]];
            bendMultiplier[k] = std::max(0.0, lastKappa * (turn - m_reachRoom[k]));
        }
        // The step taken: each segment turned by its θ (Cayley) and clamped within its joint's
        // limit against the segment before, its length within its band; then the end closed
        // again (a second-order correction): chord steps with this step's factor, the goal
        // free, and solve() with the goal kept where they put it.
        saved.assign(p.begin() + std::min(root, end), p.begin() + std::max(root, end) + 1);
        m_reachStart = d;
        const std::vector<Vec3>& start = m_reachStart;
        auto place = [&](const std::vector<double>& xs) {
            Vec3 at = q[0];
            for (size_t s = 0; s < segments; ++s) {
                const size_t v = s * static_cast<size_t>(nv);
                const Vec3 turn = xs[v] * e1[s] + xs[v + 1] * e2[s];
                Vec3 next = cayley(turn, start[s]);
                if (turn.squaredNorm() > 4.0) next.normalize(); // |θ/2| > 1
                const int js = static_cast<int>(s);
                Mat3 correction = Mat3::Identity(); // this segment's clamp alone
                bool corrected = false;
                clampDirection(next, s > 0 ? &d[s - 1] : rootDirection, h.m_cosLimit[point(js)],
                               h.m_sinLimit[point(js)], correction, corrected);
                d[s] = next;
                const size_t k = segment(js);
                const double length = std::clamp(l[s] + (stretchable ? xs[v + 2] : 0.0),
                                                 h.m_minLength[k], h.m_maxLength[k]);
                at += length * next;
                p[point(js + 1)] = at;
            }
        };
        place(m_step);
        const int hardRows = 3 * soft;
        for (int chord = 0; chord < kReachChords; ++chord) {
            RowVector open(hardRows);
            for (int b = 0; b < soft; ++b)
                open.segment<3>(3 * b) = p[point(blockPoint[b])] - blockTarget[b];
            if (open.norm() <= tolerance * rest) break;
            const RowVector multiplier =
                hardSchur.selfadjointView<Eigen::Upper>().ldlt().solve(open);
            for (int r = 0; r < hardRows; ++r) {
                const double* column = m_solved.data() + static_cast<size_t>(r) * vars;
                for (size_t v = 0; v < vars; ++v)
                    m_step[v] -= column[v] * multiplier(r);
            }
            place(m_step);
        }
        std::vector<SpanGoal> closeGoals = hardGoals;
        closeGoals.push_back({goals[static_cast<size_t>(moving)].point, p[point(goalPoint)], true});
        std::sort(closeGoals.begin(), closeGoals.end(),
                  [](const SpanGoal& g1, const SpanGoal& g2) { return g1.point < g2.point; });
        const Outcome closed =
            solve(root, end, true, endTarget, closeGoals, rootDirection, endDirection,
                  std::min(kReachCloseSteps, maxIterations - out.iterations), tolerance);
        out.iterations += closed.iterations;
        p[point(m)] = endTarget;
        const double next = distance();
        bool finite = true;
        for (int s = 1; s < m; ++s)
            finite = finite && p[point(s)].allFinite();
        if (closed.valid && finite && next < error) {
            const double gain = error - next;
            error = next;
            sigma = std::max(0.25 * sigma, 1e-6);
            if (gain <= 1e-9 * rest) break; // as near as it gets
        } else {
            std::copy(saved.begin(), saved.end(), p.begin() + std::min(root, end));
            sigma = std::min(4.0 * sigma, 1e12);
        }
    }
    if (maxIterations < wantedIterations && !out.goalsMet &&
        out.iterations + kReachCloseReserve >= maxIterations)
        h.m_budgetCut = true;
    return out;
}

} // namespace chaintube::detail
