// Google Benchmark programs for the core library. Figures go into the performance notes
// (tests/bench/PERFORMANCE-NOTES.md), never into tests.
//   ./build/tests/bench/chaintube_bench --benchmark_min_time=0.2
#include <benchmark/benchmark.h>
#include <chaintube/chaintube.h>
#include <cmath>
#include <cstring>
#include <vector>

using namespace chaintube;

namespace {
HoseSpec benchSpec(int segments)
{
    HoseSpec spec;
    spec.outerDiameter = 0.016;
    spec.segmentCount = segments;
    spec.material.expansionCoefficient = 0.1;
    spec.material.bendLimit = BendLimit::minBendRadius(0.08);
    return spec;
}

// One drag of the middle point far enough that the whole hose follows (worst case: the
// propagation runs to both ends).
void BM_DragWholeHose(benchmark::State& state)
{
    const int points = static_cast<int>(state.range(0));
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.01 * points, benchSpec(points - 1));
    const int middle = points / 2;
    int step = 0;
    for (auto _ : state) {
        const double phase = 0.1 * step++;
        const Vec3 target(0.005 * points + 0.5 * std::sin(phase), 0.5 * std::cos(phase),
                          0.3 * std::sin(0.7 * phase));
        benchmark::DoNotOptimize(hose.grab(middle, target));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DragWholeHose)->Arg(10)->Arg(100)->Arg(1000)->Arg(10000);

// A small interactive drag (1 mm per frame): propagation stops where constraints hold.
void BM_DragSmallStep(benchmark::State& state)
{
    const int points = static_cast<int>(state.range(0));
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 0.01 * points, benchSpec(points - 1));
    const int middle = points / 2;
    int step = 0;
    for (auto _ : state) {
        const double phase = 0.01 * step++;
        const Vec3 target =
            hose.point(middle) + 0.001 * Vec3(std::sin(phase), std::cos(phase), 0.0);
        benchmark::DoNotOptimize(hose.grab(middle, target));
    }
}
BENCHMARK(BM_DragSmallStep)->Arg(1000);

// The paper's target scene: 50 hoses × 100 points × 16-sided rings, every hose moving each
// frame (axis + ring frames + positions + normals).
void BM_Frame50Hoses(benchmark::State& state)
{
    const int sides = static_cast<int>(state.range(0));
    Scene scene;
    const int hoses = state.range(2) > 0 ? static_cast<int>(state.range(2)) : 50;
    for (int i = 0; i < hoses; ++i) {
        HoseSpec spec = benchSpec(99);
        spec.profile = Profile::circle(0.008, sides);
        scene.addHose(Hose::straight(Vec3(0.0, 0.0, 0.05 * i), Vec3::UnitX(), 1.0, spec));
    }
    const int moving = static_cast<int>(state.range(1));
    int frame = 0;
    for (auto _ : state) {
        ++frame;
        for (int i = 0; i < moving; ++i) {
            const double phase = 0.05 * frame + 0.3 * i;
            benchmark::DoNotOptimize(scene.hose(i).grab(
                50, Vec3(0.5 + 0.2 * std::sin(phase), 0.2 * std::cos(phase), 0.05 * i)));
        }
        benchmark::DoNotOptimize(scene.updateSurfaces());
    }
    size_t bytes = 0;
    for (int i = 0; i < hoses; ++i)
        bytes += 4 * (scene.surface(i).positions().size() + scene.surface(i).normals().size());
    state.counters["vertex_MB"] = static_cast<double>(bytes) * moving / hoses / 1e6;
}
BENCHMARK(BM_Frame50Hoses)
    ->Args({16, 50, 0})
    ->Args({16, 5, 0})
    ->Args({16, 1, 0})
    ->Args({16, 10, 10})
    ->Unit(benchmark::kMicrosecond);

// The physical bound of a frame: writing its vertex bytes once (about 1.9 MB).
void BM_MemsetFrameBytes(benchmark::State& state)
{
    std::vector<char> buffer(static_cast<size_t>(state.range(0)));
    for (auto _ : state) {
        std::memset(buffer.data(), static_cast<int>(state.iterations() & 0xff), buffer.size());
        benchmark::ClobberMemory();
    }
}
BENCHMARK(BM_MemsetFrameBytes)->Arg(50 * 100 * 17 * 24)->Unit(benchmark::kMicrosecond);
} // namespace

namespace {
// The parts of one hose's frame update, separately (100 points, 16-sided rings).
Hose bentHose()
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, benchSpec(99));
    benchmark::DoNotOptimize(hose.grab(50, Vec3(0.5, 0.3, 0.1)));
    return hose;
}

void BM_PartRingFrames(benchmark::State& state)
{
    const Hose hose = bentHose();
    TwistSeed seed;
    std::vector<RingFrame> frames;
    for (auto _ : state) {
        computeRingFrames(hose, seed, frames);
        benchmark::DoNotOptimize(frames.data());
    }
}
BENCHMARK(BM_PartRingFrames);

void BM_PartSurfaceUpdate(benchmark::State& state)
{
    const Hose hose = bentHose();
    HoseSurface surface(hose);
    for (auto _ : state) {
        surface.invalidate();
        benchmark::DoNotOptimize(surface.update(hose));
    }
}
BENCHMARK(BM_PartSurfaceUpdate);

void BM_PartGrab(benchmark::State& state)
{
    Hose hose = bentHose();
    int frame = 0;
    for (auto _ : state) {
        const double phase = 0.05 * ++frame;
        benchmark::DoNotOptimize(
            hose.grab(50, Vec3(0.5 + 0.2 * std::sin(phase), 0.2 * std::cos(phase), 0.0)));
    }
}
BENCHMARK(BM_PartGrab);

// A grab between two fixed end segments that pulls the span nearly taut (phase 2: the
// relaxation between pinned points), 100 points.
void BM_GrabBetweenFixedEnds(benchmark::State& state)
{
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, benchSpec(99));
    hose.attach(0, 1, Frame::identity());
    const int end = hose.attach(98, 99, Frame::identity());
    Frame closer;
    closer.translation = Vec3(-0.2, 0.0, 0.0);
    for (int k = 1; k <= 20; ++k) {
        closer.translation = Vec3(-0.01 * k, 0.0, 0.0);
        benchmark::DoNotOptimize(hose.moveAttachment(end, closer));
    }
    int frame = 0;
    for (auto _ : state) {
        const double t = 0.02 * ++frame;
        benchmark::DoNotOptimize(
            hose.grab(50, Vec3(0.4, 0.25 * std::sin(t), 0.15 * std::sin(2 * t))));
    }
}
BENCHMARK(BM_GrabBetweenFixedEnds);

// The end attachment of a straight inextensible hose moved 1 cm towards the other: the span is
// laid on its buckling mode (the bow) and then solved, 10 and 100 points.
void BM_BowStraightSpan(benchmark::State& state)
{
    const int segments = static_cast<int>(state.range(0));
    HoseSpec spec = benchSpec(segments);
    spec.material.expansionCoefficient = 0.0;
    const Hose straight = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec);
    Frame closer;
    closer.translation = Vec3(-0.01, 0.0, 0.0);
    for (auto _ : state) {
        state.PauseTiming();
        Hose hose = straight;
        hose.attach(0, 0, Frame::identity());
        const int end = hose.attach(segments, segments, Frame::identity());
        state.ResumeTiming();
        benchmark::DoNotOptimize(hose.moveAttachment(end, closer));
    }
}
BENCHMARK(BM_BowStraightSpan)->Arg(10)->Arg(100);
} // namespace
BENCHMARK_MAIN();
