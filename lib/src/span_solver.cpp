// SpanSolver::solve: the span's points placed by forward kinematics from its root and its goals
// met by damped Newton steps on the joint rotations (and lengths), with the active set of joints
// on their bend limits; the moment sums that assemble its normal equations in O(n).
#include "span_solver.h"

#include "banded_ldlt.h"
#include "span_kinematics.h"
#include "vector_set.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace chaintube::detail {

namespace {

/// SpanSolver::solve: the room of a free joint not worked out yet.
constexpr double kRoomUnknown = std::numeric_limits<double>::quiet_NaN();

/// Sums over a run of joints from which the normal equations' blocks of every pair of goal
/// blocks beyond the run follow in constant time. Joint s (direction d, position y relative to
/// a reference point o, bend normal n when held on its limit, length free or not) turns the
/// points beyond it: a block at a = p_b − o moves by ω × (a − y) (+ d δl), so it adds
/// [a_b − y]ᵀ Q [a_q − y] (+ d dᵀ) to block (b, q), Q = I − d dᵀ (− n nᵀ). With c = d × y and
/// e = n × y: Σ Q = count I − Σ d dᵀ − Σ n nᵀ, Σ Q [y] = [Σ y] − Σ d cᵀ − Σ n eᵀ,
/// Σ [y]ᵀ Q [y] = Σ |y|² I − Σ y yᵀ − Σ c cᵀ − Σ e eᵀ (sumYQY adds the lengths' Σ d dᵀ); each
/// sum of outer products is kept as one accumulator (three in all, not seven).
struct JointMoments
{
    /// A symmetric 3 × 3 sum (xx, yy, zz, xy, xz, yz) and a general one (row-major).
    struct Sym
    {
        double m[6] = {};
        [[gnu::always_inline]] void add(const Vec3& a)
        {
            m[0] += a.x() * a.x(), m[1] += a.y() * a.y(), m[2] += a.z() * a.z();
            m[3] += a.x() * a.y(), m[4] += a.x() * a.z(), m[5] += a.y() * a.z();
        }
        /// Adds sign · a aᵀ.
        [[gnu::always_inline]] void add(const Vec3& a, double sign)
        {
            const Vec3 s = sign * a;
            m[0] += s.x() * a.x(), m[1] += s.y() * a.y(), m[2] += s.z() * a.z();
            m[3] += s.x() * a.y(), m[4] += s.x() * a.z(), m[5] += s.y() * a.z();
        }
        Mat3 matrix() const
        {
            Mat3 r;
            r << m[0], m[3], m[4], m[3], m[1], m[5], m[4], m[5], m[2];
            return r;
        }
    };
    struct Outer
    {
        double m[9] = {};
        [[gnu::always_inline]] void add(const Vec3& a, const Vec3& b)
        {
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    m[3 * i + j] += a[i] * b[j];
        }
        Mat3 matrix() const
        {
            Mat3 r;
            r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
            return r;
        }
    };

    double count = 0.0, yy = 0.0;
    Vec3 y = Vec3::Zero();
    Sym ddNn;   ///< Σ d dᵀ + Σ n nᵀ
    Outer dcNe; ///< Σ d cᵀ + Σ n eᵀ
    Sym yyCcEe; ///< Σ y yᵀ + Σ c cᵀ + Σ e eᵀ − Σ d dᵀ of the joints whose length is free
    Vec3 heldRoom = Vec3::Zero(), heldRoomE = Vec3::Zero(); ///< Σ room n, Σ room e (held joints)
    Vec3 heldStretch = Vec3::Zero(); ///< Σ room d (held lengths: their change to their bound)

    [[gnu::always_inline]] void add(const Vec3& at, const Vec3& d, const Vec3* held, double room,
                                    bool lengthFree, double lengthRoom)
    {
        heldStretch += lengthRoom * d;
        const Vec3 c = d.cross(at);
        count += 1.0;
        yy += at.squaredNorm();
        y += at;
        yyCcEe.add(at);
        ddNn.add(d);
        dcNe.add(d, c);
        yyCcEe.add(c);
        if (lengthFree) yyCcEe.add(d, -1.0);
        if (held) {
            const Vec3& n = *held;
            const Vec3 e = n.cross(at);
            ddNn.add(n);
            dcNe.add(n, e);
            yyCcEe.add(e);
            heldRoom += room * n;
            heldRoomE += room * e;
        }
    }
    Mat3 sumQ() const { return count * Mat3::Identity() - ddNn.matrix(); }
    Mat3 sumQY() const { return skew(y) - dcNe.matrix(); }
    Mat3 sumYQY() const { return yy * Mat3::Identity() - yyCcEe.matrix(); }
};

} // namespace

void SpanBuffers::clear()
{
    clearEach(vectors());
}

void SpanBuffers::swap(SpanBuffers& other) noexcept
{
    static_assert(sizeof(SpanBuffers) == sizeOfVectors(std::tuple_size_v<decltype(vectors())>),
                  "vectors() names every vector");
    swapEach(vectors(), other.vectors());
}

SpanSolver::SpanSolver(Hose& hose) : h(hose)
{
    SpanBuffers::swap(h.m_workspace.get().span);
    SpanBuffers::clear();
}

SpanSolver::~SpanSolver()
{
    SpanBuffers::swap(h.m_workspace.get().span);
}

SpanSolver::Outcome SpanSolver::solve(int root, int end, bool endFixed, const Vec3& endTarget,
                                      const std::vector<SpanGoal>& goals, const Vec3* rootDirection,
                                      const Vec3* endDirection, int maxIterations, double tolerance,
                                      bool writeAnyway, int rejectLimit)
{
    Outcome out;
    std::vector<Vec3>& p = h.m_local;
    const int dir = end > root ? 1 : -1;
    const int m = (end - root) * dir; // segments
    if (m < 1) return out;
    // Within the update's budget (Hose::setBudget): fewer steps, the span as the last one left it.
    const int wantedIterations = maxIterations;
    maxIterations = h.budgetedSteps(maxIterations);
    // Point s of the span and the hose segment between points s and s + 1 of the span.
    auto point = [&](int s) { return static_cast<size_t>(root + dir * s); };
    auto segment = [&](int s) { return static_cast<size_t>(dir > 0 ? root + s : root - s - 1); };
    const size_t segments = static_cast<size_t>(m);
    m_direction.resize(segments);
    m_length.resize(segments);
    m_trial.resize(segments);
    m_trialLength.resize(segments);
    m_position.resize(segments + 1);
    m_savedPositions.resize(segments + 1);
    m_saturated.assign(segments, 0);
    m_lengthHeld.assign(segments, 0);
    m_lengthRoom.assign(segments, 0.0);
    m_normal.resize(segments);
    m_room.resize(segments);
    m_roomBound.resize(segments);
    m_turnSin.resize(segments);
    m_turnCos.resize(segments);
    const bool stretchable = h.m_spec.material.expansionCoefficient > 0.0;

    auto limitCos = [&](int s) { return h.m_cosLimit[point(s)]; };
    auto limitSin = [&](int s) { return h.m_sinLimit[point(s)]; };
    auto limitAngle = [&](int s) { return h.m_limitAngle[point(s)]; };
    // How far the turn of joint s may still grow (its normal set): exact once asked for.
    auto roomOf = [&](size_t k) {
        if (std::isnan(m_room[k]))
            m_room[k] = limitAngle(static_cast<int>(k)) - std::atan2(m_turnSin[k], m_turnCos[k]);
        return m_room[k];
    };
    // Whether a free joint turning by t more along its normal passes its limit (t above the
    // joint's lower bound of its room, m_roomBound: the exact room decides).
    auto passesLimit = [&](size_t k, double t) { return t > 0.0 && t > roomOf(k); };
    // The direction before segment s (null for the root without a fixed segment before it).
    auto previousOf = [&](const std::vector<Vec3>& d, int s) -> const Vec3* {
        if (s > 0) return &d[static_cast<size_t>(s - 1)];
        return rootDirection;
    };
    auto limited = [&](int s) { return previousOf(m_direction, s) && limitCos(s) > -1.0 + 1e-12; };
    // The way left from length s to the end of its band it is held at (kHeldAtMax, kHeldAtMin).
    auto lengthRoomOf = [&](int s, unsigned char bandEnd) {
        const size_t seg = segment(s);
        return (bandEnd == kHeldAtMax ? h.m_maxLength[seg] : h.m_minLength[seg]) -
               m_length[static_cast<size_t>(s)];
    };

    // Clamps every joint to its limit, in order (clampDirection): clampJoint(d, s, …) takes
    // direction s of `d`, those before it done.
    auto clampJoint = [&](std::vector<Vec3> & d, int s, Mat3& correction, bool& corrected)
        __attribute__((always_inline))
    {
        clampDirection(d[static_cast<size_t>(s)], previousOf(d, s), limitCos(s), limitSin(s),
                       correction, corrected);
    };
    auto clampChain = [&](std::vector<Vec3>& d) {
        Mat3 correction = Mat3::Identity();
        bool corrected = false;
        for (int s = 0; s < m; ++s)
            clampJoint(d, s, correction, corrected);
    };
    auto forward = [&](const std::vector<Vec3>& d, const std::vector<double>& l) {
        m_position[0] = p[static_cast<size_t>(root)];
        for (size_t s = 0; s < segments; ++s)
            m_position[s + 1] = m_position[s] + l[s] * d[s];
    };

    // The current shape as directions and lengths, every joint within its limit.
    for (size_t s = 0; s < segments; ++s) {
        const size_t k = segment(static_cast<int>(s));
        const Vec3 d = p[point(static_cast<int>(s) + 1)] - p[point(static_cast<int>(s))];
        const double length = d.norm();
        m_direction[s] =
            length > 0.0 ? Vec3(d / length) : (s > 0 ? m_direction[s - 1] : Vec3::UnitX());
        m_length[s] = std::clamp(length, h.m_minLength[k], h.m_maxLength[k]);
    }
    clampChain(m_direction);
    forward(m_direction, m_length);

    // Rows: 3 per goal, 3 for the end, 1 for the end's bend when at its limit.
    const int goalCount = static_cast<int>(std::min<size_t>(goals.size(), (kMaxRows - 4) / 3));
    const double restEnd = h.m_restLength[segment(m - 1)];
    const size_t endJoint = static_cast<size_t>(end);
    const bool endBendLimited = endFixed && endDirection && h.m_cosLimit[endJoint] > -1.0 + 1e-12;
    const double endLimit = endBendLimited ? h.m_limitAngle[endJoint] : 0.0;
    constexpr double kSoftWeight = 1e-2; // a soft goal's share of the squared residual

    bool polishing = false; // the soft goals are left out: the closure alone
    struct State
    {
        RowVector residual;
        double merit = 0.0;
        double closure = 0.0; ///< end distance (endFixed) and end bend excess, relative
        double goalError = 0.0;
        bool bendRow = false;
        double endTurn = 0.0;
    };
    auto evaluate = [&](State& st) {
        const int rows = 3 * goalCount + 3 + 1;
        st.residual.setZero(rows);
        st.merit = 0.0;
        st.goalError = 0.0;
        for (int g = 0; g < goalCount; ++g) {
            const SpanGoal& goal = goals[static_cast<size_t>(g)];
            const Vec3 r = m_position[static_cast<size_t>((goal.point - root) * dir)] - goal.target;
            st.residual.segment<3>(3 * g) = r;
            st.merit += (goal.hard ? 1.0 : (polishing ? 0.0 : kSoftWeight)) * r.squaredNorm();
            if (goal.hard) st.goalError = std::max(st.goalError, r.norm() / restEnd);
        }
        const Vec3 r = m_position[segments] - endTarget;
        st.residual.segment<3>(3 * goalCount) = r;
        st.merit += (endFixed || goalCount == 0 ? 1.0 : kSoftWeight) * r.squaredNorm();
        st.closure = endFixed ? r.norm() / restEnd : 0.0;
        st.bendRow = false;
        if (endBendLimited) {
            const Vec3& last = m_direction[segments - 1];
            const double turn =
                std::atan2(last.cross(*endDirection).norm(), last.dot(*endDirection));
            st.endTurn = turn;
            const double excess = turn - endLimit;
            st.bendRow = excess > -1e-9 * endLimit;
            if (st.bendRow) {
                st.residual(3 * goalCount + 3) = excess;
                st.merit += excess * excess * restEnd * restEnd;
                st.closure = std::max(st.closure, excess);
            }
        }
        if (!endFixed) st.goalError = std::max(st.goalError, r.norm() / restEnd);
    };

    State current;
    evaluate(current);
    double damping = 0.0;
    int rejected = 0; // steps undone
    bool anySoft = false;
    for (int g = 0; g < goalCount; ++g)
        anySoft = anySoft || !goals[static_cast<size_t>(g)].hard;
    std::vector<Vec3>& omega = m_omega;
    std::vector<double>& stretch = m_stretch;
    omega.assign(segments, Vec3::Zero());
    stretch.assign(segments, 0.0);
    const int rows = 3 * goalCount + 3 + 1;
    for (; out.iterations < maxIterations; ++out.iterations) {
        // The last two steps of the budget close the span alone (the soft goals as they are).
        if (anySoft && !polishing && maxIterations >= 4 && out.iterations >= maxIterations - 2) {
            polishing = true;
            damping = 0.0;
            evaluate(current);
        }
        // Soft goals have no tolerance: they take the budget, until a step gains nothing.
        if (current.closure <= tolerance && current.goalError <= tolerance &&
            !(anySoft && !polishing))
            break;
        // The bend row at the end, as a rotation of the last direction: g = ∂turn/∂d.
        Vec3 bendAxis = Vec3::Zero();
        if (current.bendRow) {
            const Vec3& last = m_direction[segments - 1];
            const double c = last.dot(*endDirection);
            Vec3 g = -(*endDirection - c * last);
            const double sn = g.norm();
            if (sn > 1e-12) bendAxis = last.cross(g / sn);
        }
        // Per joint: the normal of its bend plane (turning about it increases the turn) and how
        // far the turn may still grow. A free joint's room is worked out when a step might use
        // it up (roomOf); until then m_roomBound holds a lower bound: below a right angle the turn
        // is asin(sin) ≤ sin + (π/2 − 1) sin³ (the series of asin has positive terms summing to π/2
        // at 1), so most joints are decided without atan2 (−∞: the exact test, +∞: no limit to
        // pass).
        constexpr double kInfinity = std::numeric_limits<double>::infinity();
        constexpr double kAsinCubic = std::numbers::pi / 2.0 - 1.0;
        for (int s = 0; s < m; ++s) {
            const size_t k = static_cast<size_t>(s);
            if (m_lengthHeld[k]) m_lengthRoom[k] = lengthRoomOf(s, m_lengthHeld[k]);
            m_normal[k] = Vec3::Zero();
            m_room[k] = 1e300;
            m_roomBound[k] = kInfinity;
            if (!limited(s)) continue;
            const Vec3& before = *previousOf(m_direction, s);
            const Vec3 cross = before.cross(m_direction[k]);
            const double sn = cross.norm();
            m_roomBound[k] = -kInfinity;
            if (!(sn > 1e-12)) continue; // straight (or folded): no bend plane to limit in
            m_normal[k] = cross / sn;
            m_turnSin[k] = sn;
            m_turnCos[k] = before.dot(m_direction[k]);
            m_room[k] =
                m_saturated[k] ? limitAngle(s) - std::atan2(sn, m_turnCos[k]) : kRoomUnknown;
            if (!m_saturated[k] && m_turnCos[k] > 0.0)
                m_roomBound[k] = limitAngle(s) - sn * (1.0 + kAsinCubic * sn * sn);
        }
        // Blocks of three rows (the goals, then the end) and the end's bend row. Joint s turns
        // segments s … m−1 about position s: a block's point q > s moves by ω × (p_q − p_s)
        // (rows R_b = −[v_b]×), the bend row by u·ω.
        const int blocks = goalCount + 1;
        int blockPoint[kMaxRows / 3];
        for (int g = 0; g < goalCount; ++g)
            blockPoint[g] = (goals[static_cast<size_t>(g)].point - root) * dir;
        blockPoint[goalCount] = m;
        // The first block beyond joint s (blocks first … blocks − 1 lie beyond it: they are
        // sorted by point), searched on from `from` (a block at or before an earlier joint).
        auto firstBlockBeyond = [&](int s, int from) {
            while (from < blocks && blockPoint[from] <= s)
                ++from;
            return from;
        };
        const Vec3 u = bendAxis;
        // The normal equations, upper blocks: each joint adds its part (add(s, ±1) with its
        // state at the time), so a pass that holds or frees a few joints changes only theirs.
        RowMatrix raw, a;
        RowVector rawRhs, lambda, rhs;
        raw.setZero(rows, rows);
        rawRhs = -current.residual;
        // A joint's change of bend state in the normal equations (heldSign +1: held on its
        // limit, −1: freed): a joint held on its limit turns along it (its turn grows by exactly
        // its room, ≥ 0 and tiny), the rest of its rotation is free.
        auto toggle = [&](int s, int heldSign) {
            const size_t k = static_cast<size_t>(s);
            const Vec3& n = m_normal[k];
            const int first = firstBlockBeyond(s, 0);
            Vec3 e[kMaxRows / 3];
            for (int b = first; b < blocks; ++b)
                e[b] = (m_position[static_cast<size_t>(blockPoint[b])] - m_position[k]).cross(n);
            for (int b = first; b < blocks; ++b) {
                for (int q = b; q < blocks; ++q)
                    raw.block<3, 3>(3 * b, 3 * q) -= heldSign * (e[b] * e[q].transpose());
                rawRhs.segment<3>(3 * b) += heldSign * m_room[k] * e[b];
            }
            if (current.bendRow) {
                const double un = u.dot(n);
                raw(rows - 1, rows - 1) -= heldSign * un * un;
                for (int b = first; b < blocks; ++b)
                    raw.block<3, 1>(3 * b, rows - 1) += heldSign * un * e[b];
                rawRhs(rows - 1) -= heldSign * m_room[k] * un;
            }
        };
        // Every joint's part at once: the joints between consecutive block points (the run
        // before block r, whose points lie beyond them all from r on) summed as moments about
        // block r's point.
        for (int r = 0, s = 0; r < blocks; ++r) {
            JointMoments sum;
            const Vec3& origin = m_position[static_cast<size_t>(blockPoint[r])];
            for (; s < blockPoint[r]; ++s) {
                const size_t k = static_cast<size_t>(s);
                sum.add(m_position[k] - origin, m_direction[k],
                        m_saturated[k] ? &m_normal[k] : nullptr, m_room[k],
                        stretchable && !m_lengthHeld[k], m_lengthRoom[k]);
            }
            if (sum.count == 0.0) continue;
            const Mat3 q = sum.sumQ(), qy = sum.sumQY(), yqy = sum.sumYQY();
            Mat3 arm[kMaxRows / 3];
            for (int b = r; b < blocks; ++b)
                arm[b] = skew(m_position[static_cast<size_t>(blockPoint[b])] - origin);
            for (int b = r; b < blocks; ++b) {
                for (int q2 = b; q2 < blocks; ++q2)
                    raw.block<3, 3>(3 * b, 3 * q2) +=
                        -arm[b] * q * arm[q2] + arm[b] * qy - qy.transpose() * arm[q2] + yqy;
                const Vec3 toBlock = m_position[static_cast<size_t>(blockPoint[b])] - origin;
                rawRhs.segment<3>(3 * b) -=
                    sum.heldRoom.cross(toBlock) - sum.heldRoomE + sum.heldStretch;
            }
            if (current.bendRow) {
                const Vec3 qu = q * u;
                raw(rows - 1, rows - 1) += u.dot(qu);
                const Vec3 qyu = qy.transpose() * u;
                for (int b = r; b < blocks; ++b)
                    raw.block<3, 1>(3 * b, rows - 1) += arm[b].transpose() * qu - qyu;
                rawRhs(rows - 1) -= u.dot(sum.heldRoom);
            }
        }
        std::vector<ActiveChange>& changes = m_changes;
        for (int pass = 0; pass < 4; ++pass) {
            a = raw; // the upper blocks (the solve reads no more)
            rhs = rawRhs;
            for (int g = 0; g < goalCount; ++g)
                if (!goals[static_cast<size_t>(g)].hard)
                    for (int i = 0; i < 3; ++i) {
                        const int row = 3 * g + i;
                        if (polishing) {
                            a.row(row).setZero();
                            a.col(row).setZero();
                            a(row, row) = 1.0;
                            rhs(row) = 0.0;
                        } else {
                            a(row, row) *= 1.0 + 1.0 / kSoftWeight;
                        }
                    }
            if (!endFixed && goalCount > 0)
                for (int i = 0; i < 3; ++i)
                    a(3 * goalCount + i, 3 * goalCount + i) *= 1.0 + 1.0 / kSoftWeight;
            const double scale = a.diagonal().cwiseAbs().maxCoeff() + 1e-300;
            for (int i = 0; i < rows; ++i)
                a(i, i) += damping * std::abs(a(i, i)) + 1e-13 * scale;
            if (!current.bendRow) {
                a.row(rows - 1).setZero();
                a.col(rows - 1).setZero();
                a(rows - 1, rows - 1) = 1.0; // unused row
                rhs(rows - 1) = 0.0;
            }
            // Positive definite (J Jᵀ with a relative floor on the diagonal): LDLᵀ without
            // pivoting, the dense case of the band solve (a row that rounding leaves without
            // a positive pivot is dropped).
            double dense[kMaxRows * kMaxRows];
            for (int i = 0; i < rows; ++i)
                for (int j = i; j < rows; ++j)
                    dense[i * rows + (j - i)] = a(i, j);
            lambda = rhs;
            solveDenseLdlt(dense, lambda.data(), static_cast<size_t>(rows));
            // ω_s = P_s R_sᵀ λ (+ the held turn). A free joint whose turn would pass its limit
            // is held on it; a held joint that this step would turn back inside is freed.
            bool changed = false;
            changes.clear();
            const Vec3 tail = current.bendRow ? Vec3(lambda(rows - 1) * u) : Vec3::Zero();
            // Σ over the blocks beyond joint s of (p_b − p_s) × λ_b = moment[f] − (p_s − p_0) ×
            // force[f], f the first block beyond s: sums from the last block back.
            Vec3 moment[kMaxRows / 3 + 1], force[kMaxRows / 3 + 1];
            moment[blocks] = tail;
            force[blocks] = Vec3::Zero();
            for (int b = blocks - 1; b >= 0; --b) {
                const Vec3 l = lambda.segment<3>(3 * b);
                force[b] = force[b + 1] + l;
                moment[b] =
                    moment[b + 1] +
                    (m_position[static_cast<size_t>(blockPoint[b])] - m_position[0]).cross(l);
            }
            int first = 0;
            for (int s = 0; s < m; ++s) {
                const size_t k = static_cast<size_t>(s);
                const Vec3& d = m_direction[k];
                const unsigned char wasSaturated = m_saturated[k], wasLengthHeld = m_lengthHeld[k];
                first = firstBlockBeyond(s, first);
                const Vec3 full =
                    moment[first] - (m_position[k] - m_position[0]).cross(force[first]);
                Vec3 w = full - d.dot(full) * d;
                const Vec3& n = m_normal[k];
                const bool hasNormal = n.squaredNorm() > 0.0;
                if (m_saturated[k]) {
                    if (hasNormal && n.dot(w) < m_room[k]) {
                        m_saturated[k] = 0; // it would rather turn back inside
                        changed = true;
                    } else {
                        w += (m_room[k] - n.dot(w)) * n;
                    }
                } else if (!(n.dot(w) > m_roomBound[k])) {
                    // Inside the bound of its room (or no limit): stays free.
                } else if (hasNormal && passesLimit(k, n.dot(w))) {
                    m_saturated[k] = 1;
                    changed = true;
                } else if (!hasNormal && limited(s)) {
                    // A straight joint turns in the plane the step chooses: held on its limit
                    // there if the step would turn it further.
                    const double limit = limitAngle(s);
                    const double turn = w.norm();
                    if (turn > limit) {
                        m_normal[k] = w / turn;
                        m_room[k] = limit;
                        m_saturated[k] = 1;
                        changed = true;
                    }
                }
                omega[k] = w;
                if (stretchable) {
                    // A length that the step would take beyond an end of its band is held: its
                    // change is the way to that end (its room, as a held joint's turn), its row
                    // left out. Held, it is freed when the step pulls it back in.
                    const double dl = d.dot(force[first]);
                    if (m_lengthHeld[k]) {
                        if (m_lengthHeld[k] == kHeldAtMax ? dl < 0.0 : dl > 0.0) {
                            m_lengthHeld[k] = 0; // the room is taken out with its row (toggle)
                            changed = true;
                        }
                    } else if (dl != 0.0) {
                        const unsigned char bandEnd = dl > 0.0 ? kHeldAtMax : kHeldAtMin;
                        const double room = lengthRoomOf(s, bandEnd);
                        if (dl > 0.0 ? dl > room : dl < room) {
                            m_lengthHeld[k] = bandEnd;
                            m_lengthRoom[k] = room;
                            changed = true;
                        }
                    }
                    stretch[k] = m_lengthHeld[k] ? m_lengthRoom[k] : dl;
                }
                if (m_saturated[k] != wasSaturated || m_lengthHeld[k] != wasLengthHeld)
                    changes.push_back({s, wasSaturated != 0, stretchable && !wasLengthHeld});
            }
            if (!changed) break;
            // Bend states one joint at a time (toggle). A length's change adds ±d dᵀ to every
            // block pair beyond its joint and ±room d to those blocks' right-hand side: summed
            // over the joints before the same first block, and added once a run.
            JointMoments::Sym lengthBlock[kMaxRows / 3]; // zero
            Vec3 lengthRhs[kMaxRows / 3];
            std::fill(std::begin(lengthRhs), std::end(lengthRhs), Vec3::Zero());
            bool lengthChanged[kMaxRows / 3] = {};
            int firstBlock = 0;
            for (const ActiveChange& change : changes) {
                const size_t k = static_cast<size_t>(change.joint);
                const bool held = m_saturated[k] != 0, lengthFree = stretchable && !m_lengthHeld[k];
                if (held != change.held) toggle(change.joint, held ? 1 : -1);
                if (lengthFree == change.lengthFree) continue;
                firstBlock = firstBlockBeyond(change.joint, firstBlock);
                const double sign = lengthFree ? 1.0 : -1.0;
                if (firstBlock < blocks) {
                    const Vec3& d = m_direction[k];
                    lengthBlock[firstBlock].add(d, sign);
                    lengthRhs[firstBlock] += sign * m_lengthRoom[k] * d;
                    lengthChanged[firstBlock] = true;
                }
                if (lengthFree) m_lengthRoom[k] = 0.0;
            }
            for (int f = 0; f < blocks; ++f) {
                if (!lengthChanged[f]) continue;
                const Mat3 block = lengthBlock[f].matrix();
                for (int b = f; b < blocks; ++b) {
                    for (int q = b; q < blocks; ++q)
                        raw.block<3, 3>(3 * b, 3 * q) += block;
                    rawRhs.segment<3>(3 * b) += lengthRhs[f];
                }
            }
        }
        // The step: joint rotations accumulate along the chain. A Cayley rotation is
        // orthogonal: with |ω/2| ≤ 1 it keeps a unit direction unit to a few ulps (every solve
        // starts from normalised directions; over the walks of tests/ a direction's length stays
        // within 1e-13 of 1), so only larger rotations, whose rounding grows with |ω|², are
        // normalised again.
        // Each direction turned is clamped back within its limit at once (the rest of the chain
        // turning with it) and placed.
        std::swap(m_savedPositions, m_position); // every position is written
        m_position[0] = p[static_cast<size_t>(root)];
        Vec3 total = Vec3::Zero();
        Mat3 correction = Mat3::Identity();
        bool corrected = false;
        for (size_t s = 0; s < segments; ++s) {
            total += omega[s];
            m_trial[s] = cayley(total, m_direction[s]);
            if (total.squaredNorm() > 4.0) m_trial[s].normalize(); // |ω/2| > 1
            const size_t k = segment(static_cast<int>(s));
            m_trialLength[s] =
                std::clamp(m_length[s] + stretch[s], h.m_minLength[k], h.m_maxLength[k]);
            clampJoint(m_trial, static_cast<int>(s), correction, corrected);
            m_position[s + 1] = m_position[s] + m_trialLength[s] * m_trial[s];
        }
        std::swap(m_direction, m_trial);
        std::swap(m_length, m_trialLength);
        State next;
        evaluate(next);
        bool finite = true;
        for (const Vec3& x : m_position)
            finite = finite && x.allFinite();
        const bool better =
            next.merit < current.merit ||
            (next.closure < current.closure && next.merit <= current.merit * (1.0 + 1e-9));
        if (finite && better) {
            current = next;
            damping = damping > 1e-9 ? 0.25 * damping : 0.0;
        } else if (anySoft && !polishing && current.closure <= tolerance &&
                   current.goalError <= tolerance) {
            // Valid, and the Gauss–Newton step from here brings the soft goals no nearer: as
            // near as they get (in the engine sample's walk, none of the 805 soft tries whose
            // first step was undone gained anything in three more steps damped 1e-4 to 1.6e-3).
            std::swap(m_direction, m_trial);
            std::swap(m_length, m_trialLength);
            std::swap(m_position, m_savedPositions);
            break;
        } else if (endFixed && anySoft && !polishing && current.closure > tolerance) {
            // The soft goals are as near as they get: finish the closure alone.
            std::swap(m_direction, m_trial);
            std::swap(m_length, m_trialLength);
            std::swap(m_position, m_savedPositions);
            polishing = true;
            damping = 0.0;
            evaluate(current);
        } else {
            // Undo, damp harder.
            std::swap(m_direction, m_trial);
            std::swap(m_length, m_trialLength);
            std::swap(m_position, m_savedPositions);
            damping = std::max(4.0 * damping, 1e-4);
            if (++rejected == rejectLimit) {
                ++out.iterations;
                break;
            }
        }
    }
    out.valid = current.closure <= tolerance || !endFixed;
    out.goalsMet = out.valid && current.goalError <= tolerance;
    if ((out.valid || writeAnyway) && out.iterations > 0) {
        for (int s = 1; s < m; ++s)
            p[point(s)] = m_position[static_cast<size_t>(s)];
        if (!endFixed) p[point(m)] = m_position[segments];
    }
    out.closure = current.closure;
    h.spendSteps(out.iterations, maxIterations, out.goalsMet ? maxIterations : wantedIterations);
    return out;
}

} // namespace chaintube::detail
