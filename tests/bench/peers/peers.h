// Peer solvers measured side by side with ChainTube in the speed-against-error report
// (chaintube-bench-report) and the real-time benchmark (chaintube-bench-realtime).
#pragma once

#include <chaintube/types.h>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::bench {

/// Rest shape and material shared by every solver of one run.
struct RodSetup
{
    std::vector<Vec3> axis; ///< initial (rest) axis points
    double expansionCoefficient = 0.0;
    double minBendRadius = 0.0;   ///< metres; 0 = use deflectionAngle
    double deflectionAngle = 0.0; ///< radians per joint (the paper's parameter)
    bool noBendLimit = false;     ///< no bend limit at all (the catenary): overrides both above
    /// Gravity (m/s², world). Zero: the peers run quasi-static (no inertia). Non-zero: XPBD and
    /// Bullet integrate with time step `timeStep` per frame (inertia, damping); ChainTube runs
    /// one Hose::step() per frame (HoseSpec::gravity on: one implicit step of 1/90 s whose
    /// velocity carries over from frame to frame).
    Vec3 gravity = Vec3::Zero();
    double timeStep = 1.0 / 60.0;
    /// A floor: axis points stay at or above this height (world y, metres), i.e. the floor's
    /// surface plus the rod's radius. −∞ (the default): no floor. The XPBD rod lifts every free
    /// point below it back to it after each sweep; the ChainTube rod gets a MeshCollider plane
    /// (two triangles) at floorHeight − its outer radius; Bullet's rope ignores it.
    double floorHeight = -std::numeric_limits<double>::infinity();
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

/// ChainTube (the library) behind the common interface. With gravity the hose has
/// HoseSpec::gravity on and each frame (after the frame's requests) runs Hose::step(), the
/// runtime's per-frame gravity call.
std::unique_ptr<RodSolver> makeChainTubeRod(const RodSetup& setup);

/// Position-based rod: XPBD with zero compliance (hard constraints): a stretch-band constraint
/// per segment and a bend-limit constraint per joint on the distance of its neighbours
/// (|p_{i+1} − p_{i−1}| ≥ the chord of the limiting turn), `iterations` Gauss–Seidel sweeps per
/// frame. Without gravity no inertia (a quasi-static projection per frame); with gravity the
/// usual PBD integration (predict with velocity and gravity, project, velocity from the
/// positions, 2 % velocity damping per frame).
std::unique_ptr<RodSolver> makeXpbdRod(const RodSetup& setup, int iterations);

#ifdef CHAINTUBE_HAVE_BULLET
/// Bullet's soft-body rope (btSoftBodyHelpers::CreateRope), link rest lengths from the setup's
/// axis, bending links (distance-2 links, stiffness `bendStiffness` in [0, 1]) unless
/// noBendLimit; fixed nodes and grabbed nodes get zero mass and are placed at their targets
/// every frame (kinematic). A grabbed node stays kinematic from its first grab on: toggling its
/// mass back after each step would leave the links' constants stale, and the node would then
/// not pull its neighbours. One stepSimulation(timeStep) per frame
/// with `iterations` position iterations. Bullet has no bend limit, only bending stiffness.
std::unique_ptr<RodSolver> makeBulletRope(const RodSetup& setup, int iterations,
                                          double bendStiffness = 1.0);
#endif

} // namespace chaintube::bench
