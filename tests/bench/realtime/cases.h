// chaintube-bench-realtime: the hose cases (chain, pins, floor, the grabbed point's random
// walk), the per-frame checks, and one timed run of ChainTube or of the XPBD rod over a case.
// The definitions are spelled out in README.md beside this file.
#pragma once

#include <array>
#include <chaintube/hose.h>
#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace chaintube::bench::realtime {

/// An axis-aligned box, world metres.
struct Box
{
    Vec3 min = Vec3::Zero();
    Vec3 max = Vec3::Zero();
};

/// The grabbed point's target: a random walk of `step` metres a frame inside `box`, mirrored at
/// its walls. The same sequence on every platform and standard library: std::mt19937_64 (its
/// output is fixed by the C++ standard), doubles from its top 53 bits, directions by rejection
/// from the cube (no libm function involved).
class RandomWalk
{
public:
    /// `start` inside `box`; `step` (metres, > 0) smaller than the box's smallest side.
    RandomWalk(std::uint64_t seed, const Vec3& start, const Box& box, double step);
    /// The next target: `step` metres from the previous one in a uniform random direction,
    /// mirrored back into the box where it crosses a wall.
    Vec3 next();

private:
    double uniform(); ///< [0, 1)
    std::mt19937_64 m_random;
    Vec3 m_position;
    Box m_box;
    double m_step;
};

/// A chain's limits as one Hose defines them (per segment: rest, minimum and maximum length in
/// metres; per point: the deflection limit in radians, ends unused). Every solver of a case is
/// checked against the same limits.
struct ChainLimits
{
    std::vector<double> restLength, minLength, maxLength;
    std::vector<double> deflectionLimit;
    static ChainLimits of(const Hose& hose);
};

/// Largest violation of the length band (relative to the rest length, 0 within the band) and
/// of the deflection limits (radians, 0 within), measured here from the points, independently
/// of Hose::measureViolation.
struct Violation
{
    double length = 0.0;
    double bend = 0.0;
};
Violation measureViolation(const std::vector<Vec3>& points, const ChainLimits& limits);

/// What one run measured: the time of every timed frame and, outside the timed region, what
/// each update left behind (a hose case makes one update a frame, the engine one per grabbed
/// hose). Counters that do not apply to a solver or case keep their "not applicable" value
/// (false / −1).
struct FrameChecks
{
    std::vector<double> microseconds;    ///< per timed frame, wall clock (steady_clock)
    std::vector<double> cpuMicroseconds; ///< per timed frame, this thread's CPU time
    int updates = 0;                     ///< updates checked (frames × updates a frame)
    double lengthViolation = 0.0;        ///< largest over the updates (relative, own measure)
    double bendViolation = 0.0;          ///< largest over the updates (radians, own measure)
    int nonFinite = 0;                   ///< updates after which a position was NaN or Inf
    bool hasStatuses = false;            ///< ChainTube: the statuses below were counted
    std::array<int, 4> grabStatuses{};   ///< per Status (Ok, Clamped, Infeasible, InvalidInput)
    bool stepped = false;                ///< a Hose::step() ran after every grab
    std::array<int, 4> stepStatuses{};
    double grabErrorSum = 0.0; ///< metres: target to where the point is after the frame
    double grabErrorMax = 0.0;
    bool hasFloor = false;
    double floorPenetration = 0.0; ///< metres: deepest axis point below floor + radius
    int blocked = 0;               ///< ChainTube: updates with UpdateResult::blocked
    /// ChainTube: per update, the Newton steps it reported (UpdateResult::iterations; the grab's
    /// plus the step's with gravity): the work counter, bounded by the solver's budget.
    std::vector<int> iterations;
    /// ChainTube: the Newton steps an update may take by the library's stated budget
    /// (lib/README.md, "Budgets a call"; workBudget()); −1: none stated (contacts, the engine).
    int budget = -1;
    /// ChainTube: updates that took more Newton steps than `budget`.
    int overBudget = 0;
    /// ChainTube: per timed frame, the Newton steps of all its updates (the work of the frame).
    std::vector<int> frameWork;
    /// ChainTube: after the walk, the frames the last target held still took until no update
    /// was pending (UpdateResult::pending), the first frame counted; kHeldFrameLimit + 1: not
    /// within that many. −1: not measured.
    int heldFrames = -1;
    static constexpr int kHeldFrameLimit = 100;
    /// ChainTube: updates whose final status is Ok or Clamped (every constraint holds) while
    /// Hose::measureViolation() exceeds 1e-9 (with colliders: CollisionOptions::
    /// constraintTolerance). −1: not applicable.
    int statusContradicted = -1;
    /// ChainTube: the largest difference between the own measure and Hose::measureViolation()
    /// (a check of the benchmark's checker). −1: not applicable.
    double checkerDisagreement = -1.0;
};

/// Times one frame twice: the wall clock (std::chrono::steady_clock), what a frame budget is
/// about, and the thread's CPU time (CLOCK_THREAD_CPUTIME_ID), which leaves out the time the
/// thread was not running (another process on its core) and includes the CPU clock's own
/// reading (a few tenths of a microsecond).
class FrameTimer
{
public:
    void start();
    /// Appends the frame's times to checks.microseconds and checks.cpuMicroseconds.
    void stop(FrameChecks& checks);

private:
    double m_cpuStart = 0.0;
    std::chrono::steady_clock::time_point m_wallStart;
};

/// One line of the table.
struct Row
{
    std::string caseId;
    std::string solver;
    int points = 0;          ///< axis points (the engine: all hoses together)
    int updatesPerFrame = 1; ///< grabs a frame (the engine: one per grabbed hose)
    FrameChecks checks;
};

/// One case of the table (README.md has the definitions).
struct HoseCase
{
    std::string id;
    std::string title;
    bool endsFixed = false;
    bool gravity = false;
    bool floor = false;
    /// A sliding clip that never moves (identity frame) at the middle of the segment at a
    /// quarter of the hose (Hose::addClip); the XPBD rod has no sliding clip and is not run.
    bool clip = false;
    /// The hose held by its first point alone (a hose in a hand), walked in a box of the same
    /// size about where that point starts.
    bool heldEnd = false;
};
const std::vector<HoseCase>& hoseCases();

/// The Newton steps one frame of a case may take by the library's stated budgets (lib/README.md,
/// "Budgets a call"; tests/support's work_budgets.h): a grab between the fixed ends, with the
/// clip the clip's grab, with gravity the grab and a step. −1 with the floor: the contact
/// rounds' work is not part of the stated budgets.
int workBudget(const HoseCase& hoseCase);

/// The definitions shared by every case and solver.
struct CaseConstants
{
    static constexpr double length = 1.0;         ///< metres of hose
    static constexpr double span = 0.8;           ///< metres between the fixed ends
    static constexpr double minBendRadius = 0.1;  ///< metres
    static constexpr double expansion = 0.0;      ///< inextensible
    static constexpr double outerDiameter = 0.02; ///< metres (HoseSpec's default)
    static constexpr double walkStep = 0.02;      ///< metres a frame
    /// The walk's box: this fraction of the box bounding the middle point's reach (README.md).
    static constexpr double walkBoxScale = 0.6;
    /// The engine sample's walks: a box of ± this (metres) about where the point was laid.
    static constexpr double engineWalkReach = 0.05;
    static constexpr double floorGap = 0.001; ///< metres between the hose and the floor at start
    static constexpr std::uint64_t walkSeed = 20240901;
    static constexpr double xpbdTimeStep = 1.0 / 90.0; ///< seconds (90 Hz)
    static constexpr double xpbdGravity = 9.81;        ///< m/s², −y
};

/// A case at a resolution: the starting axis, the grabbed point, the walk's box, the floor.
struct CaseSetup
{
    HoseCase hoseCase;
    HoseSpec spec;
    std::vector<Vec3> axis; ///< starting axis: an S in the y = 0 plane, ends `span` apart
    int middle = 0;         ///< the grabbed point: pointCount / 2
    Box box;                ///< where the walk goes
    double floorY = 0.0;    ///< height of the floor's surface (with hoseCase.floor)

    /// The ChainTube hose of the case: the axis, the end attachments, the clip, the floor
    /// collider. Throws chaintube::Error when its starting state violates a constraint.
    Hose makeHose() const;
    RandomWalk walk() const;
};
CaseSetup caseSetup(const HoseCase& hoseCase, int points);

/// Timed runs over a case: `warmup` frames on a separate hose first (discarded), then `frames`
/// frames from the starting state, each timed and checked.
Row runChainTube(const HoseCase& hoseCase, int points, int frames, int warmup);

/// The per-update budget the ChainTube rows run under (Hose::setBudget; the runtime's for the
/// engine sample): UpdateBudget::realtime() unless --budget says otherwise.
UpdateBudget& benchBudget();
Row runXpbd(const HoseCase& hoseCase, int points, int sweeps, int frames, int warmup);

/// The machine's floor: `frames` frames of the same fixed arithmetic (a chain of dependent
/// multiply-adds, its length calibrated at the start to take about `microseconds`), timed back
/// to back with FrameTimer as the cases are, after `warmup` untimed ones. Every frame does the
/// same work, so what its p99 and worst add to its median is the machine's (interrupts, the
/// hypervisor, the timer), the share of any case's frame of that length that no solver can
/// remove. Only `microseconds` and `cpuMicroseconds` of the result are filled.
FrameChecks runFixedWork(double microseconds, int frames, int warmup);

/// Adds what one ChainTube update left to `checks`: the grab's status (and the step's, when
/// `stepped` is not null), violations by both measures, the status check, non-finite
/// positions, the grab error.
void checkChainTubeUpdate(FrameChecks& checks, const Hose& hose, const ChainLimits& limits,
                          const UpdateResult& grabbed, const UpdateResult* stepped,
                          int grabbedPoint, const Vec3& target);

} // namespace chaintube::bench::realtime
