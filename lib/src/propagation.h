// The paper's outward propagation (Schoor et al., the axis update): from a run of points
// placed by a grab or an attachment move, each point beyond it is placed against its neighbour
// towards the run, its length into the stretch band and then its bend at that neighbour within
// the limit, until an end, a pinned point or two unmoved points; O(n), one pass. Internal to
// lib/.
#pragma once

#include "chaintube/hose.h"

#include <vector>

namespace chaintube {

/// The propagation over one hose's local axis points (Hose::m_local), the held point `grabbed`
/// pinned like a fixed one.
class Solver
{
public:
    explicit Solver(Hose& hose) : h(hose), p(hose.m_local) {}
    /// The paper's update after the run first … last was placed (grab: first = last = k).
    /// `old` holds the run's positions before the move (for fallbacks).
    void propagateFromRun(int first, int last, const Vec3& oldFirst, const Vec3& oldLast);

    /// The paper's pass from a solved range lo … hi out into the free tails beyond it: each
    /// tail point is placed against its neighbour towards the range (length band, then the
    /// bend at that neighbour). With `full` every tail point is visited (for a shape that may
    /// violate its constraints anywhere); otherwise a tail stops where two consecutive points
    /// did not move. `before` holds the positions before the update (fold-back fallbacks).
    void sweepTails(int lo, int hi, const std::vector<Vec3>& before, bool full);

    /// Free spans between two pinned points (fixed or grabbed) that lie on the straight line
    /// between them (every free point within 1e-9 of the span's minimum length from the line)
    /// while that line is shorter than the span's minimum length: laid on the first buckling
    /// mode of a rod clamped at both pins (below) with the span's rest length, bulging towards
    /// anyPerpendicular(line), the fixed perpendicular of the fold-back rule. Returns whether a
    /// span was bowed; `before` receives the state before (only then).
    bool bowFlatCompressedSpans(std::vector<Vec3>& before);

    int grabbed = -1;
    int movedPoints = 0;

private:
    /// Place p[i] relative to its already-final anchor p[a] (a = i ± 1). `incoming` is the unit
    /// direction of the segment arriving at the anchor along the sweep (null: no angle check,
    /// the anchor is an end or its other neighbour is not settled). `anchorOld` is where the
    /// anchor was before this update, for the degenerate fallbacks. Returns whether p[i] moved;
    /// `direction` receives the unit direction anchor → p[i].
    [[gnu::always_inline]] inline bool place(int i, int a, const Vec3* incoming,
                                             const Vec3& anchorOld, Vec3& direction);

    /// As above with the anchor's final position passed in (a sweep carries it in registers:
    /// reading it back from memory would put a store-to-load forward on the critical path).
    /// With Fma, the final multiply-add is fused (only instantiated in FMA-targeted code).
    template <bool Fma>
    [[gnu::always_inline]] inline bool place(int i, int a, const Vec3 anchor, const Vec3* incoming,
                                             const Vec3& anchorOld, Vec3& direction, Vec3& placed);

    /// anchor + scale · w, the multiply-add fused with Fma (only instantiated in FMA-targeted
    /// code).
    template <bool Fma>
    [[gnu::always_inline]] static inline Vec3 alongFrom(const Vec3& anchor, double scale,
                                                        const Vec3& w);

    bool pinned(int i) const { return h.m_fixed[static_cast<size_t>(i)] != 0 || i == grabbed; }

    /// One outward sweep of the paper's propagation: from point `next` towards `step` (±1)
    /// until an end, a pinned point, or two consecutive unmoved points.
    struct Sweep
    {
        int next = 0;
        int step = 1;
        Vec3 incoming = Vec3::Zero(); ///< unit direction arriving at the anchor next − step
        bool haveIncoming = false;
        bool anchorMoved = true;
        Vec3 anchorOld = Vec3::Zero();
        bool active = true;
        Vec3 anchor = Vec3::Zero(); ///< final position of point next − step (set by run())
    };

    template <bool Fma> [[gnu::always_inline]] inline void advance(Sweep& s);

    /// Runs two independent sweeps interleaved: their dependency chains overlap in the CPU.
    template <bool Fma> [[gnu::always_inline]] inline void runSweeps(Sweep leftIn, Sweep rightIn);

#if defined(__x86_64__) && defined(__GNUC__)
    __attribute__((target("fma"))) void runSweepsFma(const Sweep& left, const Sweep& right);
#endif
    void run(Sweep left, Sweep right);

    /// Bend at point k between k−1 and k+1 above its limit: rotate both neighbours about p[k]
    /// in their common plane, each by half the excess (paper Fig. 8).
    void balanceJoint(int k, Vec3& leftDirection, Vec3& rightDirection, const Vec3& leftBefore,
                      const Vec3& rightBefore);

    Hose& h;
    std::vector<Vec3>& p;
    bool hitPin = false;
    bool fullSweep = false; ///< sweepTails(): visit every tail point
};

} // namespace chaintube
