// Contact that cannot tunnel, through the runtime: a thin collider of the descriptor (a plate of
// zero thickness, a 2 mm box, a knife edge) on a node that setNodeTransform moves through the
// exported test rig's hoses (each fixed at both ends), or a hose grabbed and dragged through
// it, at up to 2 m/s at 90 Hz, in seeded random passes (600; a quarter under AddressSanitizer).
// A crossing is judged in the collider's frame, independently of the library: a point of an
// axis (every point and three more per segment) whose straight path from its place before a
// frame to its place after it passes through the collider's middle (away from its free edges by
// 2 cm, where a hose may slip round them), or an axis segment that cuts the triangles after a
// frame. Each frame that leaves a crossing must report it (blocked; one that starts inside the
// collider, crossed or reported so the frame before, may end on either side), each constraint
// beyond its tolerance must come with Infeasible, and a pass that reaches a hose must report
// contacts or push it.
#include "export_test_support.h"

#include <chaintube/collision.h>
#include <chaintube/export/runtime.h>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace chaintube::exporting::testing {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr int kPasses = 150;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr int kPasses = 150;
#else
constexpr int kPasses = 600;
#endif
#else
constexpr int kPasses = 600;
#endif

constexpr double kDegree = std::numbers::pi / 180.0;

struct Blade
{
    enum Kind { Plate, Box, Knife } kind = Plate;
    double half = 0.1;  ///< plate: x, y in [−half, half]; knife: the edge's x in [−half, half]
    double depth = 0.1; ///< knife: the faces reach back to z = −depth
    rig::ColliderMesh mesh;

    void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d)
    {
        const auto base = static_cast<std::uint32_t>(mesh.positions.size() / 3);
        for (const Vec3* p : {&a, &b, &c, &d})
            for (int k = 0; k < 3; ++k)
                mesh.positions.push_back(static_cast<float>((*p)[k]));
        mesh.indices.insert(mesh.indices.end(),
                            {base, base + 1, base + 2, base, base + 2, base + 3});
    }

    static Blade make(Kind kind, double half, double angle)
    {
        Blade b;
        b.kind = kind;
        b.half = half;
        const double a = half, t = 0.001;
        if (kind == Plate) {
            b.quad({-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0});
        } else if (kind == Box) {
            b.quad({-a, -a, t}, {a, -a, t}, {a, a, t}, {-a, a, t});
            b.quad({-a, -a, -t}, {-a, a, -t}, {a, a, -t}, {a, -a, -t});
            b.quad({-a, -a, -t}, {a, -a, -t}, {a, -a, t}, {-a, -a, t});
            b.quad({-a, a, -t}, {-a, a, t}, {a, a, t}, {a, a, -t});
            b.quad({-a, -a, -t}, {-a, -a, t}, {-a, a, t}, {-a, a, -t});
            b.quad({a, -a, -t}, {a, a, -t}, {a, a, t}, {a, -a, t});
        } else {
            const double h = b.depth, w = h * std::tan(0.5 * angle);
            b.quad({-a, 0, 0}, {a, 0, 0}, {a, w, -h}, {-a, w, -h});
            b.quad({-a, 0, 0}, {-a, -w, -h}, {a, -w, -h}, {a, 0, 0});
        }
        return b;
    }

    /// Whether the straight path q0 → q1 (blade frame) passes through the blade's middle.
    bool crossed(const Vec3& q0, const Vec3& q1) const
    {
        constexpr double margin = 0.02;
        if (kind != Knife) {
            if ((q0.z() >= 0.0) == (q1.z() >= 0.0)) return false;
            const Vec3 x = q0 + (q0.z() / (q0.z() - q1.z())) * (q1 - q0);
            return std::abs(x.x()) <= half - margin && std::abs(x.y()) <= half - margin;
        }
        if ((q0.y() >= 0.0) == (q1.y() >= 0.0)) return false;
        const Vec3 x = q0 + (q0.y() / (q0.y() - q1.y())) * (q1 - q0);
        return std::abs(x.x()) <= half - margin && x.z() < -0.002 && x.z() > -depth + margin;
    }
};

std::vector<Vec3> axisSamples(const Hose& hose)
{
    std::vector<Vec3> out;
    for (int s = 0; s < hose.segmentCount(); ++s)
        for (int k = 0; k < 4; ++k)
            out.push_back(hose.point(s) + (0.25 * k) * (hose.point(s + 1) - hose.point(s)));
    out.push_back(hose.point(hose.segmentCount()));
    return out;
}

/// Largest length excess beyond the band (relative) and bend excess (radians), from scratch.
std::pair<double, double> violation(const Hose& hose)
{
    double length = 0.0, angle = 0.0;
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const double l = (hose.point(s + 1) - hose.point(s)).norm();
        length = std::max(length, std::max(l - hose.maxLength(s), hose.minLength(s) - l) /
                                      hose.restLength(s));
    }
    for (int j = 1; j < hose.segmentCount(); ++j) {
        const Vec3 a = hose.point(j) - hose.point(j - 1), b = hose.point(j + 1) - hose.point(j);
        angle = std::max(angle, std::atan2(a.cross(b).norm(), a.dot(b)) - hose.deflectionLimit(j));
    }
    return {length, angle};
}

TEST(RuntimeContact, ThinCollidersOfTheDescriptorCrossTheTestRigsHosesOnlyReported)
{
    TemporaryFolder folder;
    const fs::path output = folder / "rig.glb";
    exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
    const rig::HoseRuntime loaded = rig::HoseRuntime::load(output);
    // The blade: a root node of its own, the descriptor's only collider.
    rig::HoseRigDescriptor descriptor = loaded.descriptor();
    std::vector<rig::RigNode> nodes;
    for (int i = 0; i < loaded.nodeCount(); ++i)
        nodes.push_back(loaded.node(i));
    const int bladeNode = static_cast<int>(nodes.size());
    nodes.push_back({"blade", -1, {}});
    descriptor.colliders = {bladeNode};
    std::vector<int> pinnedBothEnds;
    for (int h = 0; h < loaded.hoseCount(); ++h)
        if (!loaded.description(h).isStatic && loaded.description(h).attachments.size() >= 2)
            pinnedBothEnds.push_back(h);
    ASSERT_FALSE(pinnedBothEnds.empty());

    std::mt19937 rng(52032u);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> normal(0.0, 1.0);
    int crossings = 0, invalid = 0, silentCrossings = 0, silentInvalid = 0, touchedPasses = 0,
        unreported = 0, frames = 0;
    std::string first;
    for (int pass = 0; pass < kPasses; ++pass) {
        const bool knife = pass % 2 == 1;
        const Blade blade = knife ? Blade::make(Blade::Knife, 0.04 + 0.06 * unit(rng),
                                                (10.0 + 50.0 * unit(rng)) * kDegree)
                                  : Blade::make(unit(rng) < 0.5 ? Blade::Plate : Blade::Box,
                                                0.04 + 0.06 * unit(rng), 0.0);
        const int h = pinnedBothEnds[static_cast<size_t>(unit(rng) * pinnedBothEnds.size())];
        const rig::RigHose& d = loaded.description(h);
        const Hose& initial = loaded.hose(h);
        // A free point in the middle 40 % between the attachments, grabbable.
        const int lo = d.attachments.front().lastPoint, hi = d.attachments.back().firstPoint;
        const int k =
            std::clamp(static_cast<int>(std::lround(lo + (hi - lo) * (0.3 + 0.4 * unit(rng)))),
                       lo + 1, hi - 1);
        Quat rotation(normal(rng), normal(rng), normal(rng), normal(rng));
        rotation.normalize();
        Vec3 direction;
        if (knife) {
            const double tilt = 30.0 * kDegree * unit(rng),
                         turn = 2.0 * std::numbers::pi * unit(rng);
            direction = rotation * Vec3(std::sin(tilt) * std::cos(turn),
                                        std::sin(tilt) * std::sin(turn), std::cos(tilt));
        } else {
            direction = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
        }
        const Vec3 target = initial.point(k);
        const Vec3 lateral = knife
                                 ? Vec3(rotation * Vec3(blade.half * (unit(rng) - 0.5), 0.0, 0.0))
                                 : Vec3(rotation * Vec3(blade.half * 1.2 * (unit(rng) - 0.5),
                                                        blade.half * 1.2 * (unit(rng) - 0.5), 0.0));
        auto placed = [&](double back) {
            rig::NodeTransform t;
            t.rotation = rotation;
            t.translation = target + lateral - back * direction;
            return t;
        };
        auto frameOf = [](const rig::NodeTransform& t) { return Frame{t.rotation, t.translation}; };
        // Just clear of every hose of the rig.
        const std::shared_ptr<MeshCollider> probe =
            MeshCollider::fromArrays(blade.mesh.positions.data(), blade.mesh.positions.size() / 3,
                                     blade.mesh.indices.data(), blade.mesh.indices.size());
        double back = 0.0;
        auto clear = [&]() {
            probe->setFrame(frameOf(placed(back)));
            for (int g = 0; g < loaded.hoseCount(); ++g)
                if (!(clearance(loaded.hose(g), *probe).distance > 0.001)) return false;
            return true;
        };
        for (int tries = 0; tries < 200 && !clear(); ++tries)
            back += 0.005;
        const double travel = back + 0.005 + 0.045 * unit(rng);
        const double speed = (0.2 + 1.8 * unit(rng)) / 90.0;
        const int count = static_cast<int>(std::ceil(travel / speed));
        const bool dragged = unit(rng) < 0.5 && std::binary_search(d.grabbablePoints.begin(),
                                                                   d.grabbablePoints.end(), k);
        // Does the pass bring the blade into the hose as it lay (so contacts must be reported)?
        // A grab must report them when the hose touches the blade where it ended.
        {
            probe->setFrame(frameOf(placed(back - travel)));
            bool touches = !dragged && clearance(initial, *probe).distance < 0.0;
            nodes[static_cast<size_t>(bladeNode)].local = placed(back);
            rig::HoseRuntime runtime = rig::HoseRuntime::fromDescriptor(
                descriptor, nodes, nullptr, std::vector<rig::ColliderMesh>{blade.mesh});
            bool reported = false, lastReported = false, wrong = false;
            std::vector<char> wasInside(static_cast<size_t>(runtime.hoseCount()), 0);
            for (int f = 1; f <= count; ++f) {
                const double moved = std::min(travel, f * speed);
                const Frame before = runtime.nodeWorldFrame(bladeNode);
                std::vector<std::vector<Vec3>> samplesBefore;
                for (int g = 0; g < runtime.hoseCount(); ++g)
                    samplesBefore.push_back(axisSamples(runtime.hose(g)));
                std::vector<UpdateResult> results(static_cast<size_t>(runtime.hoseCount()));
                if (dragged) {
                    results[static_cast<size_t>(h)] =
                        runtime.grab(h, k, target - moved * direction);
                } else {
                    for (const rig::HoseUpdate& u :
                         runtime.setNodeTransform(bladeNode, placed(back - moved)))
                        results[static_cast<size_t>(u.hose)] = u.result;
                }
                for (const UpdateResult& r : results)
                    reported |= r.contacts > 0 || r.blocked || (!dragged && r.movedPoints > 0);
                if (dragged) {
                    const UpdateResult& r = results[static_cast<size_t>(h)];
                    lastReported = r.contacts > 0 || r.blocked;
                }
                runtime.update();
                ++frames;
                const Frame after = runtime.nodeWorldFrame(bladeNode);
                const MeshCollider& collider = *runtime.colliders()[0];
                for (int g = 0; g < runtime.hoseCount(); ++g) {
                    const UpdateResult& r = results[static_cast<size_t>(g)];
                    const Hose& hose = runtime.hose(g);
                    const std::vector<Vec3> samples = axisSamples(hose);
                    bool crossed = false, cut = false;
                    for (size_t i = 0; i < samples.size() && !crossed; ++i)
                        crossed = blade.crossed(
                            before.applyInverse(samplesBefore[static_cast<size_t>(g)][i]),
                            after.applyInverse(samples[i]));
                    for (int s = 0; s < hose.segmentCount() && !cut; ++s) {
                        const MeshCollider::Closest c =
                            collider.closestToSegment(hose.point(s), hose.point(s + 1), 1e-9);
                        cut = c.found && c.distance < 1e-12;
                    }
                    crossings += crossed || cut;
                    if ((crossed || cut) && !r.blocked && !wasInside[static_cast<size_t>(g)]) {
                        ++silentCrossings;
                        wrong = true;
                    }
                    wasInside[static_cast<size_t>(g)] =
                        crossed || cut || (r.blocked && r.penetration > 0.0);
                    const auto [length, angle] = violation(hose);
                    if (!(length <= 1e-6 && angle <= 1e-6)) {
                        ++invalid;
                        if (r.status != Status::Infeasible) {
                            ++silentInvalid;
                            wrong = true;
                        }
                    }
                }
            }
            if (dragged) {
                touches = clearance(runtime.hose(h), *runtime.colliders()[0]).distance <
                          runtime.hose(h).collisionOptions().tolerance;
                reported = lastReported;
            }
            touchedPasses += touches;
            if (touches && !reported) {
                ++unreported;
                wrong = true;
            }
            if (wrong && first.empty())
                first = "pass " + std::to_string(pass) + (knife ? " knife" : " plate/box") +
                        (dragged ? " dragged" : " moved") + " hose " + d.id + " point " +
                        std::to_string(k) + ", speed " + std::to_string(speed * 90.0) +
                        " m/s, frames " + std::to_string(count);
        }
    }
    std::printf("%d passes, %d frames, %d touched a hose; frames ending with a hose crossed "
                "or cut %d, beyond a constraint %d\n",
                kPasses, frames, touchedPasses, crossings, invalid);
    EXPECT_EQ(silentCrossings, 0) << first;
    EXPECT_EQ(silentInvalid, 0) << first;
    EXPECT_EQ(unreported, 0) << first;
    EXPECT_GT(touchedPasses, kPasses / 2) << "the passes must reach the hoses";
}

} // namespace
} // namespace chaintube::exporting::testing
