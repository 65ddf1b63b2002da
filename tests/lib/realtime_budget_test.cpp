// Bounded work a frame (lib/README.md, "Grab with attachments"): a hose fixed at both ends whose
// middle is grabbed every frame on a long random walk in and beyond its reach keeps every
// constraint after every frame, never leaves a NaN, and never does more Newton steps a grab than
// the budget the README states. Work is counted (UpdateResult::iterations), never timed.
#include "test_util.h"

#include <random>

using namespace chaintube;
using namespace chaintube::test;

namespace {

/// Newton steps a grab between two fixed points may take (lib/README.md): 12 to bow a straight
/// span, 4 steps of at most 6 hard and 6 soft Newton steps to advance, 12 to solve the span again
/// with the point soft.
constexpr int kGrabBudget = 12 + 4 * (6 + 6) + 12;

struct WalkFigures
{
    int frames = 0;
    int clamped = 0;
    int maxIterations = 0;
};

/// A hose of `points` points, 1 m long, bend radius 0.1 m, inextensible, its end segments fixed
/// 0.8 m apart, laid as an arc; its middle grabbed `frames` times on a 2 cm random walk inside a
/// box that reaches beyond the middle's reach (seeded: the same walk on every platform).
WalkFigures walkTheMiddle(int points, int frames)
{
    HoseSpec spec;
    spec.segmentLength = 1.0 / (points - 1);
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = BendLimit::minBendRadius(0.1);
    // An arc of length 1 m through (0, 0, 0) and (0.8, 0, 0) bulging towards −z.
    std::vector<Vec3> axis;
    // Half the angle it subtends solves sin(h) / h = 0.8 (chord 0.8 = 2 R sin h, length 1 = 2 R h).
    double half = 1.0;
    for (int i = 0; i < 50; ++i)
        half -= (std::sin(half) - 0.8 * half) / (std::cos(half) - 0.8);
    const double radius = 0.5 / half;
    for (int i = 0; i < points; ++i) {
        const double a = -half + 2.0 * half * i / (points - 1);
        axis.emplace_back(0.4 + radius * std::sin(a), 0.0,
                          -radius * (std::cos(a) - std::cos(half)));
    }
    Hose hose = Hose::fromAxis(axis, spec);
    const int n = hose.pointCount(), middle = n / 2;
    hose.attach(0, 1, Frame::identity());
    hose.attach(n - 2, n - 1, Frame::identity());
    EXPECT_TRUE(hose.measureViolation().ok()) << "the starting arc holds every constraint";

    std::mt19937_64 random(20240901);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const Vec3 low(0.34, 0.0, -0.18), high(0.46, 0.18, 0.18); // about half of it beyond reach
    Vec3 target = hose.point(middle);
    WalkFigures figures;
    for (int frame = 0; frame < frames; ++frame) {
        Vec3 step(unit(random), unit(random), unit(random));
        target += 0.02 * step.normalized();
        target = target.cwiseMax(low).cwiseMin(high);
        const UpdateResult r = hose.grab(middle, target);
        EXPECT_TRUE(r.status == Status::Ok || r.status == Status::Clamped)
            << "frame " << frame << ": status " << static_cast<int>(r.status);
        EXPECT_LE(r.iterations, kGrabBudget) << "frame " << frame;
        const UpdateResult measured = hose.measureViolation();
        EXPECT_LE(measured.lengthViolation, 1e-9) << "frame " << frame;
        EXPECT_LE(measured.angleViolation, 1e-9) << "frame " << frame;
        bool finite = true;
        for (int i = 0; i < n; ++i)
            finite = finite && hose.point(i).allFinite();
        EXPECT_TRUE(finite) << "frame " << frame;
        if (::testing::Test::HasFailure()) break; // one frame's report is enough
        figures.clamped += r.status == Status::Clamped;
        figures.maxIterations = std::max(figures.maxIterations, r.iterations);
        ++figures.frames;
    }
    return figures;
}

/// The walk of `frames` frames at `points` points, every frame checked; the walk goes beyond
/// reach again and again (more than `clampedAtLeast` grabs Clamped): the budget is spent, not
/// merely allowed.
void expectTheWalkWithinBudget(int points, int frames, int clampedAtLeast)
{
    const WalkFigures f = walkTheMiddle(points, frames);
    EXPECT_EQ(f.frames, frames);
    EXPECT_GT(f.clamped, clampedAtLeast);
    EXPECT_GT(f.maxIterations, 24);
    std::printf("%d points: %d frames, %d clamped, at most %d Newton steps a grab (budget %d)\n",
                points, f.frames, f.clamped, f.maxIterations, kGrabBudget);
}

} // namespace

TEST(RealTimeBudget, ALongWalkBetweenFixedEndsKeepsEveryConstraintWithinTheGrabBudget25Points)
{
    expectTheWalkWithinBudget(25, 20000, 1000);
}

TEST(RealTimeBudget, ALongWalkBetweenFixedEndsKeepsEveryConstraintWithinTheGrabBudget100Points)
{
    expectTheWalkWithinBudget(100, 4000, 200);
}
