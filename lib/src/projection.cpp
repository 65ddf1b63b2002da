#include "projection.h"

#include "banded_ldlt.h"
#include "vector_set.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace chaintube::detail {

namespace {
/// A constraint within this fraction of its bound counts as on it.
constexpr double kActiveMargin = 1e-9;
/// A row outside the working set joins it when the step would take it beyond its bound by this
/// fraction of run()'s tolerance (at most kActiveMargin): a row left violated by less than the
/// margin but more than the tolerance would otherwise stay out, and the steps stall above the
/// tolerance.
constexpr double kJoinShare = 0.01;
/// Re-solves of one linearisation while its working set changes.
constexpr int kWorkingSetPasses = 4;
} // namespace

void ProjectionBuffers::clear()
{
    clearEach(vectors());
}

void ProjectionBuffers::swap(ProjectionBuffers& other) noexcept
{
    static_assert(sizeof(ProjectionBuffers) ==
                      sizeOfVectors(std::tuple_size_v<decltype(vectors())>),
                  "vectors() names every vector");
    swapEach(vectors(), other.vectors());
}

ChainProjection::ChainProjection(Hose& hose) : h(hose)
{
    ProjectionBuffers::swap(h.m_workspace.get().projection);
    ProjectionBuffers::clear();
}

ChainProjection::~ChainProjection()
{
    ProjectionBuffers::swap(h.m_workspace.get().projection);
}

void ChainProjection::setRange(int first, int last)
{
    m_first = std::max(0, first);
    m_last = std::min(h.pointCount() - 1, last);
    const size_t n = static_cast<size_t>(h.pointCount());
    if (m_inverseMass.size() != n) m_inverseMass.assign(n, 1.0);
    h.m_workingSet.assign(3 * n, 0);
    m_rows.reserve(3 * n); // a contact, a length and a bend row a point at most
    m_meanRest = h.restLengthTotal() / static_cast<double>(h.segmentCount());
}

void ChainProjection::useMassesFromRestLengths(int held)
{
    const size_t n = static_cast<size_t>(h.pointCount());
    m_inverseMass.assign(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
        if (h.m_fixed[i] || static_cast<int>(i) == held) continue;
        const double mass =
            0.5 * ((i > 0 ? h.m_restLength[i - 1] : 0.0) + (i + 1 < n ? h.m_restLength[i] : 0.0));
        m_inverseMass[i] = m_meanRest / mass;
    }
}

void ChainProjection::clearContacts()
{
    m_hasContact.clear();
}

void ChainProjection::setContact(int point, const Vec3& normal, const Vec3& onPlane,
                                 double distance)
{
    const size_t n = static_cast<size_t>(h.pointCount());
    if (m_hasContact.size() != n) {
        m_hasContact.assign(n, 0);
        m_contactNormal.assign(n, Vec3::Zero());
        m_contactPoint.assign(n, Vec3::Zero());
        m_contactDistance.assign(n, 0.0);
    }
    const size_t i = static_cast<size_t>(point);
    m_hasContact[i] = 1;
    m_contactNormal[i] = normal;
    m_contactPoint[i] = onPlane;
    m_contactDistance[i] = distance;
}

bool ChainProjection::setContact(int point, const MeshCollider::Closest& closest,
                                 const Vec3& origin, const Vec3& cameFrom, double distance,
                                 double onSurface)
{
    Vec3 normal = closest.normal;
    const Vec3 onMesh = closest.onMesh - origin;
    if (closest.distance < onSurface && normal.dot(cameFrom - onMesh) < 0.0) normal = -normal;
    if (!normal.allFinite()) return false;
    setContact(point, normal, onMesh, distance);
    return true;
}

double ChainProjection::gather(bool onlyMeasure)
{
    const std::vector<Vec3>& p = h.m_local;
    const std::vector<double>& w = m_inverseMass;
    std::vector<signed char>& work = h.m_workingSet;
    m_rows.clear();
    double worst = 0.0;
    m_merit = 0.0;
    const bool contacts = !m_hasContact.empty();
    // Unit direction of the segment before the current point, carried along the loop.
    Vec3 before = Vec3::Zero();
    double beforeLength = 0.0;
    for (int i = m_first; i <= m_last; ++i) {
        const size_t k = static_cast<size_t>(i);
        if (contacts && m_hasContact[k] && w[k] > 0.0) {
            const double value =
                m_contactDistance[k] - m_contactNormal[k].dot(p[k] - m_contactPoint[k]);
            worst = std::max(worst, value / m_meanRest);
            if (value > 0.0) m_merit += (value / m_meanRest) * (value / m_meanRest);
            if (!onlyMeasure) {
                Row row;
                row.first = i;
                row.count = 1;
                row.g[0] = -m_contactNormal[k];
                row.value = value;
                row.key = 3 * k;
                row.inequality = true;
                row.working = value > -kActiveMargin * m_meanRest || work[row.key] != 0;
                m_rows.push_back(row);
            }
        }
        if (i == m_last) break;
        const Vec3 d = p[k + 1] - p[k];
        const double length = d.norm();
        const double lo = h.m_minLength[k], hi = h.m_maxLength[k], rest = h.m_restLength[k];
        const Vec3 unit = length > 0.0 ? Vec3(d / length) : Vec3::Zero();
        if (w[k] + w[k + 1] > 0.0) {
            const double excess = std::max(length - hi, lo - length) / rest;
            worst = std::max(worst, excess);
            const double over = std::max(excess, 0.0); // branch-free: its sign is a coin toss
            m_merit += over * over;
            // Equality, or the bound nearer than half the band: a candidate row.
            const bool equality = lo == hi;
            const double sign = (equality || length >= rest) ? 1.0 : -1.0;
            const bool near =
                equality || (sign > 0.0 ? length > 0.5 * (hi + rest) : length < 0.5 * (lo + rest));
            if (!onlyMeasure && near && length > 0.0) {
                Row row;
                row.first = i;
                row.count = 2;
                row.g[0] = -sign * unit;
                row.g[1] = sign * unit;
                row.value = sign > 0.0 ? length - hi : lo - length;
                row.key = 3 * k + 1;
                row.inequality = !equality;
                row.working =
                    equality || row.value > -kActiveMargin * rest || work[row.key] == sign;
                row.side = static_cast<signed char>(sign);
                m_rows.push_back(row);
            }
        }
        // The bend at joint i, between the segment before it and this one (only joints whose
        // three points lie in the range).
        if (m_bends && i > m_first && h.m_cosLimit[k] > -1.0 + 1e-12 && beforeLength > 0.0 &&
            length > 0.0 && w[k - 1] + w[k] + w[k + 1] > 0.0) {
            const double cosTurn = before.dot(unit);
            // Candidates: turning by more than half the limit (cos φ < cos(θ/2)).
            if (cosTurn < h.m_cosHalfLimit[k] || work[3 * k + 2] != 0) {
                const Vec3 normal = before.cross(unit);
                const double sinTurn = normal.norm();
                const double turn = std::atan2(sinTurn, cosTurn);
                const double limit = h.m_limitAngle[k];
                const double value = turn - limit;
                worst = std::max(worst, value);
                if (value > 0.0) m_merit += value * value;
                // A straight or folded joint has no usable gradient: left to the decided rules.
                if (!onlyMeasure && sinTurn > 1e-12) {
                    const Vec3 e1 = (unit - cosTurn * before).normalized();
                    const Vec3 e2 = (before - cosTurn * unit).normalized();
                    Row row;
                    row.first = i - 1;
                    row.count = 3;
                    row.g[0] = e1 / beforeLength;
                    row.g[2] = -e2 / length;
                    row.g[1] = -row.g[0] - row.g[2];
                    row.value = value;
                    row.compliance = m_bendCompliance;
                    row.key = 3 * k + 2;
                    row.inequality = true;
                    row.working = value > -kActiveMargin * limit || work[row.key] != 0;
                    // Rows stay ordered by their first point: this one starts at i − 1, before
                    // the rows of point i.
                    size_t at = m_rows.size();
                    while (at > 0 && m_rows[at - 1].first > row.first)
                        --at;
                    m_rows.insert(m_rows.begin() + static_cast<std::ptrdiff_t>(at), row);
                }
            } else if (work[3 * k + 2] != 0) {
                work[3 * k + 2] = 0;
            }
        }
        before = unit;
        beforeLength = length;
    }
    return worst;
}

void ChainProjection::buildSystem()
{
    const std::vector<double>& w = m_inverseMass;
    const size_t m = m_rows.size();
    // Band width: rows are ordered by first point and touch at most three points, so row r
    // couples only with rows starting no later than its last point.
    m_width = 1;
    for (size_t r = 0, s = 0; r < m; ++r) {
        const int lastPoint = m_rows[r].first + m_rows[r].count - 1;
        s = std::max(s, r);
        while (s + 1 < m && m_rows[s + 1].first <= lastPoint)
            ++s;
        m_width = std::max(m_width, s - r + 1);
    }
    const size_t width = m_width;
    m_factored = false;
    m_system.resize(m * width); // every entry the solve reads is written below
    m_systemRhs.resize(m);
    for (size_t r = 0; r < m; ++r) {
        const Row& a = m_rows[r];
        m_systemRhs[r] = -a.value;
        // Row s ≥ r starts at or after row r (the order): they share the points from its first
        // to the end of the shorter, none once it starts beyond row r's last point.
        const int end = a.first + a.count;
        double* entries = &m_system[r * width];
        size_t s = r;
        for (; s < m && s < r + width && m_rows[s].first < end; ++s) {
            const Row& b = m_rows[s];
            const int hi = std::min(end, b.first + b.count);
            double value = 0.0;
            for (int point = b.first; point < hi; ++point)
                value +=
                    w[static_cast<size_t>(point)] * a.g[point - a.first].dot(b.g[point - b.first]);
            entries[s - r] = value;
        }
        for (; s < r + width; ++s)
            entries[s - r] = 0.0;
        double& diagonal = entries[0];
        diagonal += (a.compliance + m_damping) * diagonal + 1e-14 * diagonal;
    }
}

bool ChainProjection::solveWorking()
{
    const size_t m = m_rows.size(), width = m_width;
    m_step.assign(static_cast<size_t>(m_last - m_first + 1), Vec3::Zero());
    if (std::none_of(m_rows.begin(), m_rows.end(), [](const Row& row) { return row.working; })) {
        m_factored = false; // nothing solved: the next solve factors the whole band
        return true;
    }
    // The system of every candidate row, those outside the working set decoupled (a unit
    // diagonal, no coupling, right-hand side 0: multiplier 0). The solve skips zero couplings,
    // so the working rows' multipliers come out as from the system of those rows alone.
    // After a change of the working set, a band of contacts (width 7 and more) is factored
    // again only from the changed rows (the same result): replaying a row's elimination costs
    // O(width), eliminating it O(width²). On narrower bands the restore and the replays cost
    // as much as they save (tests/bench/PERFORMANCE-NOTES.md).
    if (m_factored && width >= 7) {
        m_working.resize(m);
        for (size_t r = 0; r < m; ++r)
            m_working[r] = m_rows[r].working;
        m_lambda.resize(m);
        resolveBandedLdltTwisted(m_band.data(), m_lambda.data(), m, width, m_changedFirst,
                                 m_changedLast, m_system.data(), m_systemRhs.data(),
                                 m_working.data());
    } else {
        m_band = m_system;
        m_lambda = m_systemRhs;
        for (size_t r = 0; r < m; ++r) {
            if (m_rows[r].working) continue;
            std::fill_n(m_band.begin() + static_cast<std::ptrdiff_t>(r * width), width, 0.0);
            m_band[r * width] = 1.0;
            for (size_t d = 1; d < width && d <= r; ++d)
                m_band[(r - d) * width + d] = 0.0;
            m_lambda[r] = 0.0;
        }
        solveBandedLdltTwisted(m_band.data(), m_lambda.data(), m, width);
        m_factored = true;
    }
    for (size_t r = 0; r < m; ++r) {
        const Row& a = m_rows[r];
        if (!a.working) continue;
        for (int q = 0; q < a.count; ++q)
            m_step[static_cast<size_t>(a.first + q - m_first)] += m_lambda[r] * a.g[q];
    }
    for (const Vec3& s : m_step)
        if (!s.allFinite()) return false;
    return true;
}

bool ChainProjection::adjustWorkingSet()
{
    const std::vector<double>& w = m_inverseMass;
    bool changed = false;
    m_changedFirst = m_rows.size();
    m_changedLast = 0;
    auto change = [&](size_t r) {
        changed = true;
        m_changedFirst = std::min(m_changedFirst, r);
        m_changedLast = std::max(m_changedLast, r);
    };
    // Working inequality rows whose multiplier pulls (the step needs no push from them) leave.
    for (size_t r = 0; r < m_rows.size(); ++r) {
        Row& row = m_rows[r];
        if (row.working && row.inequality && m_lambda[r] > 0.0) {
            row.working = false;
            change(r);
        }
    }
    // Rows outside the working set that the step would violate join.
    for (size_t r = 0; r < m_rows.size(); ++r) {
        Row& row = m_rows[r];
        if (row.working) continue;
        double linear = row.value;
        for (int q = 0; q < row.count; ++q) {
            const size_t k = static_cast<size_t>(row.first + q);
            linear += row.g[q].dot(w[k] * m_step[static_cast<size_t>(row.first + q - m_first)]);
        }
        const double scale = row.count == 2 ? h.m_restLength[static_cast<size_t>(row.first)] : 1.0;
        if (linear > m_joinMargin * scale) {
            row.working = true;
            change(r);
        }
    }
    return changed;
}

bool ChainProjection::lengthsOnly() const
{
    if (!m_hasContact.empty()) return false;
    for (int i = m_first; i < m_last; ++i) {
        const size_t k = static_cast<size_t>(i);
        if (h.m_minLength[k] != h.m_maxLength[k]) return false;
        if (m_bends && i > m_first && h.m_cosLimit[k] > -1.0 + 1e-12) return false;
    }
    return true;
}

double ChainProjection::gatherLengths()
{
    const std::vector<Vec3>& p = h.m_local;
    const std::vector<double>& w = m_inverseMass;
    const size_t m = static_cast<size_t>(std::max(0, m_last - m_first));
    m_unit.resize(m);
    m_systemRhs.resize(m);
    double worst = 0.0;
    m_merit = 0.0;
    for (size_t j = 0; j < m; ++j) {
        const size_t k = static_cast<size_t>(m_first) + j;
        const Vec3 d = p[k + 1] - p[k];
        const double length = d.norm();
        m_unit[j] = length > 0.0 ? Vec3(d / length) : Vec3::Zero();
        m_systemRhs[j] = length - h.m_maxLength[k]; // C(x)
        if (w[k] + w[k + 1] > 0.0) {
            const double excess = std::abs(m_systemRhs[j]) / h.m_restLength[k];
            worst = std::max(worst, excess);
            m_merit += excess * excess;
        }
    }
    return worst;
}

bool ChainProjection::solveLengths()
{
    const std::vector<double>& w = m_inverseMass;
    const size_t first = static_cast<size_t>(m_first);
    const size_t m = m_unit.size();
    // Row j: the length of segment first + j, gradient −u_j at its first point and +u_j at its
    // second; left out (multiplier 0) where both its points are fixed or it has no length.
    // (J W Jᵀ)_jj = (w_a + w_b) |u_j|², and rows j − 1, j couple through their shared point a:
    // −w_a u_{j−1} · u_j. LDLᵀ downwards (the factors l_j in m_band, D⁻¹ L⁻¹ b in m_lambda),
    // then substituted back; a vanishing pivot drops its row as the banded solve does.
    m_band.assign(m, 0.0);
    m_lambda.assign(m, 0.0);
    bool previous = false; // row j − 1 is in the system
    double previousInverse = 0.0, previousY = 0.0;
    for (size_t j = 0; j < m; ++j) {
        const size_t k = first + j;
        const Vec3& u = m_unit[j];
        if (!hasLengthRow(j)) {
            previous = false;
            continue;
        }
        const double uu = u.dot(u);
        double diagonal = w[k] * uu + w[k + 1] * uu;
        diagonal += m_damping * diagonal + 1e-14 * diagonal;
        double y = -m_systemRhs[j];
        if (previous) {
            const double coupling = -w[k] * m_unit[j - 1].dot(u);
            const double factor = coupling * previousInverse;
            m_band[j - 1] = factor;
            diagonal -= factor * coupling;
            y -= factor * previousY;
        }
        previous = diagonal > 1e-300 && std::isfinite(diagonal);
        if (!previous) continue;
        previousInverse = 1.0 / diagonal;
        previousY = y;
        m_lambda[j] = y * previousInverse;
    }
    for (size_t j = m; j-- > 1;)
        m_lambda[j - 1] -= m_band[j - 1] * m_lambda[j];
    m_step.assign(m + 1, Vec3::Zero());
    for (size_t j = 0; j < m; ++j) {
        const Vec3 g = m_lambda[j] * m_unit[j];
        m_step[j] -= g;
        m_step[j + 1] += g;
    }
    for (const Vec3& s : m_step)
        if (!s.allFinite()) return false;
    return true;
}

double ChainProjection::violation()
{
    return gather(true);
}

ProjectionOutcome ChainProjection::run(int maxIterations, double tolerance)
{
    std::vector<Vec3>& p = h.m_local;
    const std::vector<double>& w = m_inverseMass;
    ProjectionOutcome out;
    // Within the update's budget (Hose::setBudget): fewer steps, the points as the last one left.
    const int wantedIterations = maxIterations;
    maxIterations = h.budgetedSteps(maxIterations);
    m_joinMargin = std::min(kActiveMargin, kJoinShare * tolerance);
    const bool lengths = lengthsOnly();
    if (lengths) m_rows.clear();
    auto measure = [&] { return lengths ? gatherLengths() : gather(false); };
    double worst = measure();
    double merit = m_merit;
    m_damping = 0.0;
    for (; out.iterations < maxIterations && !(worst <= tolerance); ++out.iterations) {
        bool finite = true;
        if (lengths) {
            finite = solveLengths();
        } else {
            buildSystem();
            finite = solveWorking();
            for (int pass = 1; finite && pass < kWorkingSetPasses && adjustWorkingSet(); ++pass)
                finite = solveWorking();
        }
        m_saved.assign(p.begin() + m_first, p.begin() + m_last + 1);
        if (finite) {
            for (int i = m_first; i <= m_last; ++i) {
                const size_t k = static_cast<size_t>(i);
                if (w[k] != 0.0) p[k] += w[k] * m_step[static_cast<size_t>(i - m_first)];
            }
        }
        const double next = finite ? measure() : std::numeric_limits<double>::infinity();
        // Levenberg–Marquardt: a step that does not lower the squared violations is undone and
        // the next one damped harder; a good one relaxes the damping.
        if (!(m_merit < merit) && !(next < worst)) {
            std::copy(m_saved.begin(), m_saved.end(), p.begin() + m_first);
            worst = measure();
            merit = m_merit;
            m_damping = std::max(4.0 * m_damping, 1e-3);
            continue;
        }
        if (lengths) {
            // Every length row is working on its upper side (gather()'s rows of equal bounds).
            for (size_t j = 0; j < m_unit.size(); ++j)
                if (hasLengthRow(j)) h.m_workingSet[3 * (static_cast<size_t>(m_first) + j) + 1] = 1;
        }
        for (const Row& row : m_rows)
            h.m_workingSet[row.key] = row.working ? (row.side != 0 ? row.side : 1) : 0;
        worst = next;
        merit = m_merit;
        m_damping = m_damping > 1e-6 ? 0.25 * m_damping : 0.0;
    }
    out.violation = worst;
    out.converged = worst <= tolerance;
    h.spendSteps(out.iterations, maxIterations, out.converged ? maxIterations : wantedIterations);
    return out;
}

} // namespace chaintube::detail
