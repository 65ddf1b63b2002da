#include "cases.h"

#include "peers.h"

#include <algorithm>
#include <chaintube/collision.h>
#include <chaintube/test_support/work_budgets.h>
#include <cmath>
#include <ctime>
#include <limits>
#include <memory>
#include <numbers>

namespace chaintube::bench::realtime {

namespace {
double threadCpuMicroseconds()
{
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return 1e6 * static_cast<double>(now.tv_sec) + 1e-3 * static_cast<double>(now.tv_nsec);
}

void countStatus(std::array<int, 4>& counts, Status status)
{
    ++counts[static_cast<size_t>(status)];
}

bool allFinite(const std::vector<Vec3>& points)
{
    return std::all_of(points.begin(), points.end(), [](const Vec3& p) { return p.allFinite(); });
}

// `points` − 1 equal chords of the hose's length in the y = 0 plane from (0, 0, 0) to
// (span, 0, 0): an S of two circular arcs, point-symmetric about the span's centre (the first
// half turns by θ at each joint, the second by −θ; with an even number of segments the middle
// joint is straight, with an odd one the middle segment is centred on the span's centre). The
// end-to-end distance falls as θ grows; bisection finds the θ that spans `span`, then the
// polygon is turned about y so that its ends lie on the x axis: the first half bulges towards
// −z, the second towards +z (by 0.127 m for a 1 m hose over 0.8 m).
std::vector<Vec3> sAxis(int points, double length, double span)
{
    const int m = points - 1;
    const double l = length / m;
    auto polygon = [&](double turn) {
        std::vector<Vec3> axis = {Vec3::Zero()};
        double direction = 0.0;
        for (int k = 0; k < m; ++k) {
            if (k > 0) {                     // the joint at point k
                const int twice = 2 * k - m; // < 0 in the first half, > 0 in the second
                direction += twice < 0 ? turn : twice > 0 ? -turn : 0.0;
            }
            axis.push_back(axis.back() + l * Vec3(std::cos(direction), 0.0, std::sin(direction)));
        }
        return axis;
    };
    auto spanOf = [&](double turn) {
        const std::vector<Vec3> axis = polygon(turn);
        return (axis.back() - axis.front()).norm();
    };
    double lo = 0.0, hi = 4.0 * std::numbers::pi / m; // each half turns by at most 2π
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        (spanOf(mid) > span ? lo : hi) = mid;
    }
    std::vector<Vec3> axis = polygon(0.5 * (lo + hi));
    const Vec3 ends = axis.back() - axis.front();
    const double angle = std::atan2(ends.z(), ends.x()); // turn the ends onto +x
    const Mat3 rotation = Eigen::AngleAxisd(angle, Vec3::UnitY()).toRotationMatrix();
    for (Vec3& p : axis)
        p = rotation * p;
    return axis;
}

std::shared_ptr<MeshCollider> floorCollider(double y)
{
    // Two triangles, far larger than anywhere the hose can reach; normals +y.
    const std::vector<Vec3> corners = {Vec3(-2.0, y, -2.0), Vec3(3.0, y, -2.0), Vec3(3.0, y, 2.0),
                                       Vec3(-2.0, y, 2.0)};
    return MeshCollider::fromArrays(corners, {0, 2, 1, 0, 3, 2});
}

void checkFloor(FrameChecks& checks, const std::vector<Vec3>& points, double floorY, double radius)
{
    for (const Vec3& p : points)
        checks.floorPenetration = std::max(checks.floorPenetration, floorY + radius - p.y());
}

// Checks shared by every solver: positions finite, the own violation measure, the grab error.
void checkPoints(FrameChecks& checks, const std::vector<Vec3>& points, const ChainLimits& limits,
                 int grabbedPoint, const Vec3& target)
{
    ++checks.updates;
    if (!allFinite(points)) ++checks.nonFinite;
    const Violation own = measureViolation(points, limits);
    checks.lengthViolation = std::max(checks.lengthViolation, own.length);
    checks.bendViolation = std::max(checks.bendViolation, own.bend);
    const double grabError = (points[static_cast<size_t>(grabbedPoint)] - target).norm();
    checks.grabErrorSum += grabError;
    checks.grabErrorMax = std::max(checks.grabErrorMax, grabError);
}

/// `iterations` dependent multiply-adds from `x` (each waits for the last: a fixed latency).
double fixedWork(long iterations, double x)
{
    for (long i = 0; i < iterations; ++i)
        x = x * 0.9999999 + 1e-7;
    return x;
}
} // namespace

FrameChecks runFixedWork(double microseconds, int frames, int warmup)
{
    // Calibration: the fastest of 50 runs of a trial length, scaled to the frame's length.
    constexpr long kTrial = 20000;
    volatile double sink = 1.0;
    double fastest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 50; ++k) {
        const auto start = std::chrono::steady_clock::now();
        sink = fixedWork(kTrial, sink);
        fastest = std::min(fastest, std::chrono::duration<double, std::micro>(
                                        std::chrono::steady_clock::now() - start)
                                        .count());
    }
    const long iterations =
        std::max(1L, std::lround(static_cast<double>(kTrial) * microseconds / fastest));
    FrameChecks checks;
    checks.microseconds.reserve(static_cast<size_t>(frames));
    checks.cpuMicroseconds.reserve(static_cast<size_t>(frames));
    for (int f = 0; f < warmup; ++f)
        sink = fixedWork(iterations, sink);
    FrameTimer timer;
    for (int f = 0; f < frames; ++f) {
        timer.start();
        sink = fixedWork(iterations, sink);
        timer.stop(checks);
    }
    return checks;
}

void FrameTimer::start()
{
    m_cpuStart = threadCpuMicroseconds();
    m_wallStart = std::chrono::steady_clock::now();
}

void FrameTimer::stop(FrameChecks& checks)
{
    const std::chrono::steady_clock::time_point wallEnd = std::chrono::steady_clock::now();
    const double cpuEnd = threadCpuMicroseconds();
    checks.microseconds.push_back(
        std::chrono::duration<double, std::micro>(wallEnd - m_wallStart).count());
    checks.cpuMicroseconds.push_back(cpuEnd - m_cpuStart);
}

RandomWalk::RandomWalk(std::uint64_t seed, const Vec3& start, const Box& box, double step)
    : m_random(seed), m_position(start), m_box(box), m_step(step)
{
}

double RandomWalk::uniform()
{
    return static_cast<double>(m_random() >> 11) * 0x1.0p-53;
}

Vec3 RandomWalk::next()
{
    Vec3 direction;
    double squared = 0.0;
    do { // uniform in the unit ball (rejection from the cube), then onto the sphere
        const double x = 2.0 * uniform() - 1.0;
        const double y = 2.0 * uniform() - 1.0;
        const double z = 2.0 * uniform() - 1.0;
        direction = Vec3(x, y, z);
        squared = direction.squaredNorm();
    } while (!(squared > 1e-6 && squared <= 1.0));
    m_position += (m_step / std::sqrt(squared)) * direction;
    for (int k = 0; k < 3; ++k) { // mirror at the walls (a step is shorter than the box)
        if (m_position[k] < m_box.min[k]) m_position[k] = 2.0 * m_box.min[k] - m_position[k];
        if (m_position[k] > m_box.max[k]) m_position[k] = 2.0 * m_box.max[k] - m_position[k];
        m_position[k] = std::clamp(m_position[k], m_box.min[k], m_box.max[k]);
    }
    return m_position;
}

ChainLimits ChainLimits::of(const Hose& hose)
{
    ChainLimits limits;
    for (int s = 0; s < hose.segmentCount(); ++s) {
        limits.restLength.push_back(hose.restLength(s));
        limits.minLength.push_back(hose.minLength(s));
        limits.maxLength.push_back(hose.maxLength(s));
    }
    limits.deflectionLimit.assign(static_cast<size_t>(hose.pointCount()), std::numbers::pi);
    for (int j = 1; j + 1 < hose.pointCount(); ++j)
        limits.deflectionLimit[static_cast<size_t>(j)] = hose.deflectionLimit(j);
    return limits;
}

Violation measureViolation(const std::vector<Vec3>& points, const ChainLimits& limits)
{
    Violation violation;
    for (size_t s = 0; s + 1 < points.size(); ++s) {
        const double length = (points[s + 1] - points[s]).norm();
        const double excess = std::max(length - limits.maxLength[s], limits.minLength[s] - length);
        violation.length = std::max(violation.length, excess / limits.restLength[s]);
    }
    for (size_t j = 1; j + 1 < points.size(); ++j) {
        const Vec3 in = points[j] - points[j - 1], out = points[j + 1] - points[j];
        const double turn = std::atan2(in.cross(out).norm(), in.dot(out));
        violation.bend = std::max(violation.bend, turn - limits.deflectionLimit[j]);
    }
    return violation;
}

const std::vector<HoseCase>& hoseCases()
{
    static const std::vector<HoseCase> cases = {
        {"free-drag", "free hose, middle point dragged", false, false, false},
        {"ends-fixed", "both ends fixed 0.8 m apart, middle point on the walk", true, false, false},
        {"ends-fixed-gravity", "the same with per-frame gravity (Hose::step() after each grab)",
         true, true, false},
        {"ends-fixed-floor", "the same without gravity, with a floor collider under it", true,
         false, true},
        {"ends-fixed-gravity-floor", "gravity and the floor: a hose lying on a floor", true, true,
         true},
        {"ends-fixed-clip", "ends fixed, a sliding clip at a quarter, middle point on the walk",
         true, false, false, true},
        {"held-end-gravity",
         "held by one end alone on the walk, per-frame gravity (a hose in a "
         "hand)",
         false, true, false, false, true},
    };
    return cases;
}

CaseSetup caseSetup(const HoseCase& hoseCase, int points)
{
    using C = CaseConstants;
    CaseSetup setup;
    setup.hoseCase = hoseCase;
    setup.spec.outerDiameter = C::outerDiameter;
    setup.spec.material.expansionCoefficient = C::expansion;
    setup.spec.material.bendLimit = BendLimit::minBendRadius(C::minBendRadius);
    setup.spec.gravity.enabled = hoseCase.gravity; // direction −y
    setup.axis = sAxis(points, C::length, C::span);
    setup.middle = points / 2;
    // The box bounding the middle point's reach between the fixed ends (spheres of half the
    // length about each end), above the ends' plane, scaled by walkBoxScale about the span's
    // centre: x in [0.34, 0.46], y in [0, 0.18], z in [-0.18, 0.18] m.
    const double half = 0.5 * C::length;
    const double reach = std::sqrt(half * half - 0.25 * C::span * C::span);
    const double scale = C::walkBoxScale;
    setup.box.min = Vec3(0.5 * C::span - scale * (half - 0.5 * C::span), 0.0, -scale * reach);
    setup.box.max =
        Vec3(0.5 * C::span + scale * (half - 0.5 * C::span), scale * reach, scale * reach);
    setup.floorY = -(0.5 * C::outerDiameter + C::floorGap);
    if (hoseCase.heldEnd) {
        // The same box about the first point (the walk starts there).
        const Vec3 shift = setup.axis.front() - Vec3(0.5 * C::span, 0.0, 0.0);
        setup.box.min += shift;
        setup.box.max += shift;
        setup.middle = 0;
    }
    return setup;
}

Hose CaseSetup::makeHose() const
{
    Hose hose = Hose::fromAxis(axis, spec);
    const int n = hose.pointCount();
    if (hoseCase.endsFixed) {
        hose.attach(0, 1, Frame::identity());
        hose.attach(n - 2, n - 1, Frame::identity());
    }
    if (hoseCase.clip) {
        const int segment = (n - 1) / 4; // the segment at a quarter of the hose
        double place = 0.5 * hose.restLength(segment);
        for (int s = 0; s < segment; ++s)
            place += hose.restLength(s);
        static_cast<void>(hose.addClip(place, Frame::identity()));
    }
    if (hoseCase.floor) hose.setColliders({floorCollider(floorY)});
    const UpdateResult start = hose.measureViolation();
    if (!start.ok())
        throw Error("case " + hoseCase.id + ": the starting state violates a constraint (length " +
                    std::to_string(start.lengthViolation) + ", bend " +
                    std::to_string(start.angleViolation) + ")");
    return hose;
}

RandomWalk CaseSetup::walk() const
{
    return RandomWalk(CaseConstants::walkSeed, axis[static_cast<size_t>(middle)], box,
                      CaseConstants::walkStep);
}

int workBudget(const HoseCase& hoseCase)
{
    using namespace test_support;
    if (!hoseCase.endsFixed) return -1;
    if (hoseCase.clip) return kClipGrabBudget;
    if (hoseCase.floor)
        return hoseCase.gravity ? kContactGrabBudget + kStepBudget + kContactBudget
                                : kContactGrabBudget;
    return hoseCase.gravity ? kGrabBudget + kStepBudget : kGrabBudget;
}

void checkChainTubeUpdate(FrameChecks& checks, const Hose& hose, const ChainLimits& limits,
                          const UpdateResult& grabbed, const UpdateResult* stepped,
                          int grabbedPoint, const Vec3& target)
{
    checks.hasStatuses = true;
    countStatus(checks.grabStatuses, grabbed.status);
    if (stepped) {
        checks.stepped = true;
        countStatus(checks.stepStatuses, stepped->status);
    }
    if (grabbed.blocked || (stepped && stepped->blocked)) ++checks.blocked;
    checks.iterations.push_back(grabbed.iterations + (stepped ? stepped->iterations : 0));
    if (checks.budget >= 0 && checks.iterations.back() > checks.budget) ++checks.overBudget;
    const std::vector<Vec3> points = hose.points();
    checkPoints(checks, points, limits, grabbedPoint, target);

    const Violation own = measureViolation(points, limits);
    const UpdateResult library = hose.measureViolation();
    checks.checkerDisagreement =
        std::max({checks.checkerDisagreement, 0.0,
                  std::abs(own.length - std::max(0.0, library.lengthViolation)),
                  std::abs(std::max(0.0, own.bend) - std::max(0.0, library.angleViolation))});
    // Ok and Clamped promise that every constraint holds (hose.h); with colliders, to the
    // contact rounds' tolerance.
    const Status final = stepped ? stepped->status : grabbed.status;
    const double tolerance =
        hose.colliders().empty() ? 1e-9 : hose.collisionOptions().constraintTolerance;
    checks.statusContradicted = std::max(checks.statusContradicted, 0);
    if ((final == Status::Ok || final == Status::Clamped) &&
        (library.lengthViolation > tolerance || library.angleViolation > tolerance))
        ++checks.statusContradicted;
}

UpdateBudget& benchBudget()
{
    static UpdateBudget budget = UpdateBudget::realtime();
    return budget;
}

Row runChainTube(const HoseCase& hoseCase, int points, int frames, int warmup)
{
    const CaseSetup setup = caseSetup(hoseCase, points);
    {
        Hose hose = setup.makeHose();
        hose.setBudget(benchBudget());
        RandomWalk walk = setup.walk();
        for (int f = 0; f < warmup; ++f) {
            static_cast<void>(hose.grab(setup.middle, walk.next())); // warm-up: results not needed
            if (hoseCase.gravity) static_cast<void>(hose.step());
        }
    }
    Hose hose = setup.makeHose();
    hose.setBudget(benchBudget());
    const ChainLimits limits = ChainLimits::of(hose);
    RandomWalk walk = setup.walk();
    Row row{hoseCase.id, "ChainTube", points, 1, {}};
    FrameChecks& checks = row.checks;
    checks.hasFloor = hoseCase.floor;
    checks.budget = workBudget(hoseCase);
    checks.microseconds.reserve(static_cast<size_t>(frames));
    checks.cpuMicroseconds.reserve(static_cast<size_t>(frames));
    FrameTimer timer;
    for (int f = 0; f < frames; ++f) {
        const Vec3 target = walk.next();
        timer.start();
        const UpdateResult grabbed = hose.grab(setup.middle, target);
        UpdateResult stepped;
        if (hoseCase.gravity) stepped = hose.step(); // the runtime's per-frame call
        timer.stop(checks);
        checkChainTubeUpdate(checks, hose, limits, grabbed, hoseCase.gravity ? &stepped : nullptr,
                             setup.middle, target);
        checks.frameWork.push_back(grabbed.iterations + stepped.iterations);
        if (hoseCase.floor) checkFloor(checks, hose.points(), setup.floorY, hose.outerRadius());
        if (f + 1 < frames) continue;
        // The last target held still (untimed): the frames until nothing is pending.
        for (checks.heldFrames = 1; checks.heldFrames <= FrameChecks::kHeldFrameLimit;
             ++checks.heldFrames) {
            const UpdateResult held = hose.grab(setup.middle, target);
            UpdateResult heldStep;
            if (hoseCase.gravity) heldStep = hose.step();
            if (!held.pending && !heldStep.pending) break;
        }
    }
    return row;
}

Row runXpbd(const HoseCase& hoseCase, int points, int sweeps, int frames, int warmup)
{
    using C = CaseConstants;
    const CaseSetup setup = caseSetup(hoseCase, points);
    const Hose reference = setup.makeHose(); // the limits every solver is checked against
    const ChainLimits limits = ChainLimits::of(reference);
    RodSetup rod;
    rod.axis = setup.axis;
    rod.expansionCoefficient = C::expansion;
    rod.minBendRadius = C::minBendRadius;
    if (hoseCase.gravity) {
        rod.gravity = Vec3(0.0, -C::xpbdGravity, 0.0);
        rod.timeStep = C::xpbdTimeStep;
    }
    if (hoseCase.floor) rod.floorHeight = setup.floorY + reference.outerRadius();
    auto makeSolver = [&] {
        std::unique_ptr<RodSolver> solver = makeXpbdRod(rod, sweeps);
        if (hoseCase.endsFixed) { // the same one-segment attachments as the hose's
            solver->fixStart(2);
            solver->fixEnd(2);
        }
        return solver;
    };
    FrameRequest request;
    request.grabs = {{setup.middle, Vec3::Zero()}};
    {
        std::unique_ptr<RodSolver> solver = makeSolver();
        RandomWalk walk = setup.walk();
        for (int f = 0; f < warmup; ++f) {
            request.grabs.front().second = walk.next();
            solver->step(request);
        }
    }
    std::unique_ptr<RodSolver> solver = makeSolver();
    RandomWalk walk = setup.walk();
    Row row{hoseCase.id, solver->name(), points, 1, {}};
    FrameChecks& checks = row.checks;
    checks.hasFloor = hoseCase.floor;
    checks.microseconds.reserve(static_cast<size_t>(frames));
    checks.cpuMicroseconds.reserve(static_cast<size_t>(frames));
    FrameTimer timer;
    for (int f = 0; f < frames; ++f) {
        const Vec3 target = walk.next();
        request.grabs.front().second = target;
        timer.start();
        solver->step(request);
        timer.stop(checks);
        const std::vector<Vec3> positions = solver->points();
        checkPoints(checks, positions, limits, setup.middle, target);
        if (hoseCase.floor) checkFloor(checks, positions, setup.floorY, reference.outerRadius());
    }
    return row;
}

} // namespace chaintube::bench::realtime
