#include "span_solver.h"

#include "banded_ldlt.h"
#include "vector_set.h"
#include "workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
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
/// SpanSolver::reach: active-set passes a step (each one factor of the band).
constexpr int kReachPasses = 4;
/// SpanSolver::reach: chord steps that close the span after a step, then Newton steps of
/// solve() at most (a step whose closing fails in fewer leaves more of the budget to the next).
constexpr int kReachChords = 2;
constexpr int kReachCloseSteps = 5;
/// SpanSolver::reach: the budget a step needs left to be tried.
constexpr int kReachCloseReserve = 3;
/// SpanSolver::solve: the room of a free joint not worked out yet.
constexpr double kRoomUnknown = std::numeric_limits<double>::quiet_NaN();
/// SpanSolver::solve: m_lengthHeld, the end of its band a length is held at (0: free).
constexpr unsigned char kHeldAtMax = 1, kHeldAtMin = 2;
constexpr int kMaxRows = 16; // position blocks of 3 (goals and the end) and the end's bend row
using RowVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRows, 1>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxRows>;

/// Rotates x by the Cayley rotation of ω (exactly orthogonal, first order the rotation vector).
[[gnu::always_inline]] inline Vec3 cayley(const Vec3& omega, const Vec3& x)
{
    const Vec3 a = 0.5 * omega;
    const double k = 2.0 / (1.0 + a.squaredNorm());
    const Vec3 ax = a.cross(x);
    return x + k * (ax + a.cross(ax));
}

/// Rotation matrix taking unit vector `from` to unit vector `to` about their common normal.
Mat3 rotationBetween(const Vec3& from, const Vec3& to)
{
    const Vec3 axis = from.cross(to);
    const double s = axis.norm(), c = from.dot(to);
    if (!(s > 1e-300)) return Mat3::Identity();
    const Vec3 u = axis / s;
    Mat3 k;
    k << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
    return Mat3::Identity() + s * k + (1.0 - c) * k * k;
}

/// clampDirection's clamp of a direction beyond its limit (out of line: about one call of
/// clampDirection in twenty needs it in the real-time walks).
[[gnu::noinline]] void clampBeyondLimit(Vec3& ds, const Vec3* before, double cosLimit,
                                        double sinLimit, Mat3& correction, bool& corrected)
{
    const Vec3 unit = ds.normalized();
    const double c = before->dot(unit);
    Vec3 w = unit - c * *before;
    if (!(w.norm() > 1e-12)) w = anyPerpendicular(*before);
    const Vec3 clamped = (cosLimit * *before + sinLimit * w.normalized()).normalized();
    correction = rotationBetween(unit, clamped) * correction;
    corrected = true;
    ds = clamped;
}

/// Takes direction `ds` through the correction so far (the rotations of the joints clamped
/// before it) and clamps it to its limit against `before` (null: no limit), composing its own
/// clamp into the correction so that the rest of the chain turns with it (the joints after it
/// keep their turns). The corrections are built from unit vectors, so they are orthogonal and
/// the directions they turn stay unit to rounding.
[[gnu::always_inline]] inline void clampDirection(Vec3& ds, const Vec3* before, double cosLimit,
                                                  double sinLimit, Mat3& correction,
                                                  bool& corrected)
{
    if (corrected) ds = correction * ds;
    if (!before || !(cosLimit > -1.0 + 1e-12)) return;
    // before·ds ≥ cos·|ds|, without the square root where both sides are positive.
    const double dot = before->dot(ds);
    if (cosLimit >= 0.0 ? dot >= 0.0 && dot * dot >= cosLimit * cosLimit * ds.squaredNorm()
                        : dot >= cosLimit * ds.norm())
        return;
    clampBeyondLimit(ds, before, cosLimit, sinLimit, correction, corrected);
}

/// The cross-product matrix [a]: [a] x = a × x.
Mat3 skew(const Vec3& a)
{
    Mat3 k;
    k << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
    return k;
}

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
