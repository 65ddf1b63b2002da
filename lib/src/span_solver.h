// The span solver: a free span between two pinned points solved in the hose's own degrees of
// freedom (segment directions and, with a stretch band, lengths), so that every length and bend
// limit holds by construction and only the far end's closure is iterated. Internal to lib/.
#pragma once

#include "chaintube/hose.h"

#include <tuple>
#include <vector>

namespace chaintube::detail {

/// The fixed perpendicular of a unit vector: u × the world axis it has the smallest component
/// along (the fold-back rule's plane, lib/README.md).
inline Vec3 anyPerpendicular(const Vec3& u)
{
    const Vec3 a = u.cwiseAbs();
    Vec3 axis = Vec3::UnitX();
    if (a.y() <= a.x() && a.y() <= a.z())
        axis = Vec3::UnitY();
    else if (a.z() <= a.x() && a.z() <= a.y())
        axis = Vec3::UnitZ();
    return u.cross(axis).normalized();
}

/// A point of the span that should be at `target` (local coordinates).
struct SpanGoal
{
    int point = -1;
    Vec3 target = Vec3::Zero();
    bool hard = true; ///< false: as near as the span allows (least squares)
};

/// Solves the span root … end of a hose's axis: root stays where it is; the
/// points between are placed by forward kinematics from root along unit segment directions at
/// lengths inside their band (so every segment is inside its band and every joint within its
/// deflection limit, exactly, after every step); the goals are met by damped Newton steps on
/// the joint rotations (and the lengths of a stretchable hose), O(end − root) each. The end
/// point is a goal too: when `endFixed`, the span is valid only if it reaches the end point
/// (closure to `tolerance` relative to the last segment's rest length); otherwise the end is a
/// free point placed by the kinematics (a span ending at a grabbed point).
///
/// Joints at their limit may turn along the limit or back inside it, never beyond; the bend at
/// the root (from the segment before root, when `rootDirection` is set) and at the end (to
/// the segment after it, `endDirection`) are limited too.
/// A joint whose active-set state a pass of SpanSolver::solve changed: its state before.
struct SpanActiveChange
{
    int joint = 0;
    bool held = false;       ///< on its bend limit
    bool lengthFree = false; ///< its length free to change (a stretchable hose, not held)
};

/// SpanSolver's vectors, kept in the hose's workspace between solvers (each solver starts
/// with them empty, as if new).
struct SpanBuffers
{
    std::vector<SpanActiveChange> m_changes;
    std::vector<Vec3> m_saved, m_savedPositions;
    std::vector<Vec3> m_direction, m_trial, m_position;
    std::vector<double> m_length, m_trialLength, m_room, m_roomBound, m_turnSin, m_turnCos;
    std::vector<Vec3> m_normal, m_omega;
    std::vector<double> m_stretch;
    std::vector<unsigned char> m_saturated;
    std::vector<unsigned char> m_lengthHeld; ///< a length held at an end of its band (which)
    std::vector<double> m_lengthRoom;        ///< a held length's change to that end
    // reach(): the span's state, the step's band, its rows' columns
    std::vector<Vec3> m_reachDirection, m_reachFirst, m_reachSecond, m_reachPositions, m_reachStart;
    std::vector<double> m_reachLength, m_band, m_columns, m_solved, m_rhs, m_step;
    std::vector<Vec3> m_reachNormal;
    std::vector<double> m_reachRoom;
    std::vector<unsigned char> m_reachHeld;
    void clear();
    /// Exchanges every vector with `other`'s (their storage, no element moved).
    void swap(SpanBuffers& other) noexcept;

private:
    auto vectors()
    {
        return std::tie(m_changes, m_saved, m_savedPositions, m_direction, m_trial, m_position,
                        m_length, m_trialLength, m_room, m_roomBound, m_turnSin, m_turnCos,
                        m_normal, m_omega, m_stretch, m_saturated, m_lengthHeld, m_lengthRoom,
                        m_reachDirection, m_reachFirst, m_reachSecond, m_reachPositions,
                        m_reachStart, m_reachLength, m_band, m_columns, m_solved, m_rhs, m_step,
                        m_reachNormal, m_reachRoom, m_reachHeld);
    }
};

class SpanSolver : private SpanBuffers
{
public:
    /// Takes the hose's span-solver buffers for its lifetime (a solver made while another one
    /// holds them starts with its own).
    explicit SpanSolver(Hose& hose);
    ~SpanSolver();
    SpanSolver(const SpanSolver&) = delete;
    SpanSolver& operator=(const SpanSolver&) = delete;

    struct Outcome
    {
        bool valid = false;    ///< every constraint of the span holds (closure included)
        bool goalsMet = false; ///< and every goal is met to the tolerance
        int iterations = 0;
        double closure = 0.0; ///< distance of the end from its target (relative), bend excess there
    };

    /// root, end: point indices. endTarget: where the end point must be (endFixed) or should be.
    /// goals: inner points that should be at targets (sorted by point). rootDirection /
    /// endDirection: unit directions of the fixed segments before root and after end (null:
    /// none). Writes the points root + 1 … end − 1 (and end, when not endFixed) on success;
    /// leaves them as they were otherwise.
    /// root > end solves the span the other way round (root is still the point that stays).
    /// writeAnyway: write the points even when the end was not reached (the best state found).
    /// rejectLimit: give up (not valid) after this many Newton steps had to be undone (0: never).
    Outcome solve(int root, int end, bool endFixed, const Vec3& endTarget,
                  const std::vector<SpanGoal>& goals, const Vec3* rootDirection,
                  const Vec3* endDirection, int maxIterations, double tolerance,
                  bool writeAnyway = false, int rejectLimit = 0);

    /// From a valid span (its end reached), brings one point towards `target` in steps that
    /// each end valid: a sub-goal at most a trust radius away (doubled after a step that
    /// reached it, halved after one that failed), solved with every other goal and the end
    /// hard. `moving` is the index in `goals` of the point that moves, or −1 for the end
    /// itself (a span ending at a grabbed point: `endTarget` is then ignored). The span stays
    /// valid whatever happens; `goalsMet` says whether the point got to its target. At most
    /// `maxSteps` steps; for a target that moved since the last call for this point they start
    /// from a whole trust radius and end after `movingSteps` that brought the point nearer (after
    /// one step when the last call got it no nearer);
    /// when the last call stopped short of the same target they start from the radius it ended
    /// with (Hose::m_trustCarry; an inner point only).
    /// `requested` (a grab's target beyond reach, of which `target` is the nearest point within
    /// the reach balls): a step that takes the point farther from it is not taken.
    Outcome advance(int root, int end, const Vec3& endTarget, std::vector<SpanGoal> goals,
                    int moving, const Vec3& target, const Vec3* rootDirection,
                    const Vec3* endDirection, int maxSteps, int movingSteps, int stepIterations,
                    double tolerance, const Vec3* requested = nullptr);

    /// From a valid span (its end reached), brings goal `moving` as near `target` as the span
    /// allows (a held target beyond reach): SQP steps on min ½|p − target|² subject to the end's
    /// closure, the other goals and the bend limits and length bands, in each segment's own
    /// rotation across it (and its length), with the Lagrangian's curvature: a stretch's
    /// sideways stiffness under tension, and the curved cone of a joint on its limit. Each step
    /// is one factor of a block-tridiagonal band and one banded solve a row (goals and end),
    /// O(end − root); the span is then closed again (chord steps with that factor, then solve()
    /// with the point kept where they put it), and the step is taken only when the point ends
    /// nearer, so the span stays valid whatever happens. `iterations` counts the steps and the
    /// closing Newton steps. `metric`: the step's metric to start from (σ of σ·rest² a squared
    /// turn), and on return the one it ended with, for the next call of the same held target.
    Outcome reach(int root, int end, const Vec3& endTarget, const std::vector<SpanGoal>& goals,
                  int moving, const Vec3& target, const Vec3* rootDirection,
                  const Vec3* endDirection, int maxIterations, double tolerance, double& metric);

private:
    using ActiveChange = SpanActiveChange;

    Hose& h;
};

} // namespace chaintube::detail
