// Peer solvers measured side by side with ChainTube in the speed-against-error report.
#pragma once

#include <chaintube/types.h>

#include <memory>
#include <string>
#include <vector>

namespace chaintube::bench {

/// Rest shape and material shared by every solver of one run.
struct RodSetup
{
    std::vector<Vec3> axis;       ///< initial (rest) axis points
    double expansionCoefficient = 0.0;
    double minBendRadius = 0.0;   ///< metres; 0 = use deflectionAngle
    double deflectionAngle = 0.0; ///< radians per joint (the paper's parameter)
};

/// One frame of a scenario, solver-independent: optional frames for the fixed start and end
/// runs, and optional grabs (point, target) that hold only for this frame.
struct FrameRequest
{
    bool moveStart = false, moveEnd = false;
    Frame start, end;
    std::vector<std::pair<int, Vec3>> grabs;
};

/// A chain solver that runs scenarios: fixed runs at the start/end (rigid, following frames)
/// and per-frame grabs.
class RodSolver
{
public:
    virtual ~RodSolver() = default;
    virtual std::string name() const = 0;
    /// Fix the first / last `count` points rigidly to a frame (identity at call time).
    virtual void fixStart(int count) = 0;
    virtual void fixEnd(int count) = 0;
    virtual void step(const FrameRequest& request) = 0;
    virtual std::vector<Vec3> points() const = 0;
};

/// ChainTube (the library) behind the common interface.
std::unique_ptr<RodSolver> makeChainTubeRod(const RodSetup& setup);

/// Position-based rod: XPBD with zero compliance (hard constraints) and no inertia, i.e. a
/// Gauss–Seidel constraint projection per frame: a stretch-band constraint per segment and a
/// bend-limit constraint per joint on the distance of its neighbours (|p_{i+1} − p_{i−1}| ≥
/// the chord of the limiting turn). `iterations` sweeps per frame.
std::unique_ptr<RodSolver> makeXpbdRod(const RodSetup& setup, int iterations);

#ifdef CHAINTUBE_HAVE_BULLET
/// Bullet's soft-body rope (btSoftBodyHelpers::CreateRope) with bending links (distance-2
/// links), no gravity; fixed and grabbed nodes get zero mass and are placed at their targets;
/// one stepSimulation(1/60 s) per frame with `iterations` position iterations. Bullet has no
/// bend limit, only bending stiffness.
std::unique_ptr<RodSolver> makeBulletRope(const RodSetup& setup, int iterations);
#endif

} // namespace chaintube::bench
