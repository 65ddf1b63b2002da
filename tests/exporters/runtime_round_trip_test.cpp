// Round trip: project → export → HoseRuntime::load → the same axis and surface as the library
// computes, after a sequence of scene-object moves and grabs; and posing the exported skin with
// the runtime's joint transforms reproduces the library's surface.
#include "export_test_support.h"

#include <Eigen/Geometry>
#include <chaintube/export/runtime.h>
#include <chaintube/formats/collider_exemption.h>
#include <chaintube/formats/project_hoses.h>
#include <chaintube/surface.h>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>

namespace chaintube::exporting::testing {
namespace {

constexpr double kTolerance = 1e-6; // metres
// A hose once clamped, with independent frames (see Reference): input rounding grown by the
// clamped solve, not an error of the pipeline.
constexpr double kClampedTolerance = 1e-4; // metres

/// The library side: the project's hoses, built as formats builds them, with their surfaces.
struct LibraryReference
{
    formats::Project project;
    formats::ImportedScenes scenes;
    std::vector<Hose> hoses;
    std::vector<HoseSurface> surfaces;
    /// Per hose, per attachment: scene id and node index.
    std::vector<std::vector<std::pair<std::string, int>>> attachedNodes;
    /// Per hose, per clip: scene id and node index.
    std::vector<std::vector<std::pair<std::string, int>>> clippedNodes;
    /// The project's colliders (scene id, node index) and the library's MeshColliders.
    std::vector<std::pair<std::string, int>> colliderNodes;
    std::vector<std::shared_ptr<MeshCollider>> colliders;
};

formats::Mat4 matrixOf(const rig::NodeTransform& trs);

/// The collider mesh of glTF node `node` of the export (its triangle primitives, node frame).
rig::ColliderMesh colliderMeshOf(const GltfDocument& exported, int node)
{
    rig::ColliderMesh mesh;
    const Json& meshJson =
        exported.json["meshes"]
                     [exported.json["nodes"][static_cast<size_t>(node)]["mesh"].get<size_t>()];
    for (const Json& primitive : meshJson["primitives"]) {
        const std::vector<float> positions =
            floatAccessor(exported, primitive["attributes"]["POSITION"].get<int>());
        const auto first = static_cast<std::uint32_t>(mesh.positions.size() / 3);
        const Json& accessor = exported.json["accessors"][primitive["indices"].get<size_t>()];
        const Json& view = exported.json["bufferViews"][accessor["bufferView"].get<size_t>()];
        const size_t start =
            view.value("byteOffset", size_t{0}) + accessor.value("byteOffset", size_t{0});
        const bool narrow = accessor["componentType"].get<int>() == 5123;
        for (size_t i = 0; i < accessor["count"].get<size_t>(); ++i) {
            std::uint32_t index = 0;
            if (narrow) {
                std::uint16_t v = 0;
                std::memcpy(&v, exported.bin.data() + start + 2 * i, 2);
                index = v;
            } else {
                std::memcpy(&index, exported.bin.data() + start + 4 * i, 4);
            }
            mesh.indices.push_back(first + index);
        }
        mesh.positions.insert(mesh.positions.end(), positions.begin(), positions.end());
    }
    return mesh;
}

/// Gives the library's hoses the project's colliders, as the runtime does: one MeshCollider per
/// collider node (the exported mesh, placed by the scene's world transform of the node, or by
/// the runtime's with sameFrames), used by every hose except those attached to that node or to
/// a node under it (formats/collider_exemption.h, the runtime's rule).
void attachColliders(LibraryReference& reference, const GltfDocument& exported,
                     const rig::HoseRuntime& runtime, bool sameFrames)
{
    const std::vector<int>& colliderNodes = runtime.descriptor().colliders;
    ASSERT_EQ(colliderNodes.size(), reference.project.colliders.size());
    for (size_t c = 0; c < colliderNodes.size(); ++c) {
        const formats::ColliderNode& node = reference.project.colliders[c];
        const formats::ImportedScene& scene = reference.scenes.at(node.scene);
        const int index = scene.findNode(node.node);
        reference.colliderNodes.emplace_back(node.scene, index);
        Eigen::Matrix4d world = scene.worldTransform(index);
        if (sameFrames) {
            world = Eigen::Matrix4d::Identity();
            for (int n = colliderNodes[c]; n >= 0; n = runtime.node(n).parent)
                world = matrixOf(runtime.node(n).local) * world;
        }
        reference.colliders.push_back(
            rig::HoseRuntime::buildCollider(colliderMeshOf(exported, colliderNodes[c]), world));
    }
    for (size_t h = 0; h < reference.hoses.size(); ++h) {
        std::vector<std::shared_ptr<const MeshCollider>> used;
        for (size_t c = 0; c < reference.colliders.size(); ++c) {
            const auto& [colliderScene, colliderNode] = reference.colliderNodes[c];
            const formats::ImportedScene& scene = reference.scenes.at(colliderScene);
            const auto parentOf = [&](int n) { return scene.nodes[static_cast<size_t>(n)].parent; };
            bool exempt = false;
            for (const auto* held : {&reference.attachedNodes[h], &reference.clippedNodes[h]})
                for (const auto& [heldScene, heldNode] : *held)
                    exempt =
                        exempt || (heldScene == colliderScene &&
                                   formats::attachmentExempts(heldNode, colliderNode, parentOf));
            if (!exempt) used.push_back(reference.colliders[c]);
        }
        if (!used.empty()) reference.hoses[h].setColliders(std::move(used));
    }
}

LibraryReference buildReference(const fs::path& projectFile)
{
    LibraryReference reference;
    reference.project = loadWithRoots(projectFile);
    reference.scenes = formats::importProjectScenes(reference.project, projectFile, roots());
    reference.hoses = formats::buildHoses(reference.project, reference.scenes);
    for (size_t h = 0; h < reference.hoses.size(); ++h) // as the export writes gravity hoses
        formats::settleUnderGravity(reference.hoses[h], reference.project.hoses[h],
                                    reference.project, reference.scenes);
    for (const Hose& hose : reference.hoses)
        reference.surfaces.emplace_back(hose);
    for (const formats::HoseDefinition& definition : reference.project.hoses) {
        reference.attachedNodes.emplace_back();
        for (const formats::HoseAttachment& a : definition.attachments)
            reference.attachedNodes.back().emplace_back(
                a.scene, reference.scenes.at(a.scene).findNode(a.node));
        reference.clippedNodes.emplace_back();
        for (const formats::HoseClip& c : definition.clips)
            reference.clippedNodes.back().emplace_back(
                c.scene, reference.scenes.at(c.scene).findNode(c.node));
    }
    return reference;
}

formats::Mat4 matrixOf(const rig::NodeTransform& trs)
{
    formats::Mat4 m = formats::Mat4::Identity();
    m.block<3, 3>(0, 0) = Eigen::Quaterniond(trs.rotation).toRotationMatrix() *
                          Eigen::Vector3d(trs.scale).asDiagonal();
    m.block<3, 1>(0, 3) = Eigen::Vector3d(trs.translation);
    return m;
}

struct Deviation
{
    double axis = 0.0;
    double surface = 0.0;
    double skinned = 0.0;
    double staticPhase = 0.0; ///< radians: ring phase of static plain meshes against the library
};

/// Largest distance between runtime and library: axis points, surface vertices (world), and
/// the exported bind-pose mesh skinned with the runtime's joint poses; of hose `only`, or of
/// every hose when `only` is negative.
Deviation compare(const rig::HoseRuntime& runtime, const LibraryReference& reference,
                  const GltfDocument& exported, int only = -1)
{
    Deviation deviation;
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        if (only >= 0 && h != only) continue;
        const Hose& library = reference.hoses[static_cast<size_t>(h)];
        const Hose& running = runtime.hose(h);
        EXPECT_EQ(running.pointCount(), library.pointCount());
        for (int i = 0; i < library.pointCount(); ++i)
            deviation.axis = std::max(deviation.axis, (running.point(i) - library.point(i)).norm());

        const HoseSurface& librarySurface = reference.surfaces[static_cast<size_t>(h)];
        const std::vector<float> world = runtime.worldPositions(h);
        const std::span<const float> local = librarySurface.positions();
        EXPECT_EQ(world.size(), local.size());
        for (size_t v = 0; v < std::min(world.size(), local.size()); ++v)
            deviation.surface = std::max(
                deviation.surface, std::abs(static_cast<double>(world[v]) -
                                            (static_cast<double>(local[v]) +
                                             library.origin()(static_cast<Eigen::Index>(v % 3)))));

        // Skinning: vertex = jointWorld · inverseBind · bindPosition, rigid weights.
        const rig::RigHose& d = runtime.description(h);
        const Json& node = exported.json["nodes"][static_cast<size_t>(d.meshNode)];
        const Json& primitive =
            exported.json["meshes"][node["mesh"].get<size_t>()]["primitives"][0];
        const std::vector<float> bind =
            floatAccessor(exported, primitive["attributes"]["POSITION"].get<int>());
        if (d.isStatic) {
            // A plain mesh: vertex = world(mesh node, with its moved ancestors) · position.
            EXPECT_TRUE(runtime.jointPoses(h).empty());
            formats::Mat4 placement = formats::Mat4::Identity();
            for (int n = d.meshNode; n >= 0; n = runtime.node(n).parent)
                placement = matrixOf(runtime.node(n).local) * placement;
            // The node moves the mesh rigidly, while the library carries ring twist by
            // rotation-minimising frames: the tubes coincide (each vertex in its ring's plane at
            // the library's distance from the ring centre), the polygon's phase about the axis
            // may differ (reported, not a shape error).
            const std::vector<std::uint32_t>& vertexRing = librarySurface.topology().vertexRing;
            const std::vector<RingFrame>& rings = librarySurface.frames();
            EXPECT_EQ(bind.size() / 3, vertexRing.size());
            for (size_t v = 0; v < std::min(bind.size() / 3, vertexRing.size()); ++v) {
                const Vec3 placed = (placement * Eigen::Vector4d(bind[3 * v], bind[3 * v + 1],
                                                                 bind[3 * v + 2], 1.0))
                                        .head<3>();
                const Vec3 expected =
                    library.origin() +
                    Vec3(local[3 * v], local[3 * v + 1], local[3 * v + 2]).cast<double>();
                const RingFrame& ringFrame = rings[vertexRing[v]];
                const Vec3 centre = library.origin() + ringFrame.center;
                const Vec3 fromCentre = placed - centre, expectedFromCentre = expected - centre;
                const double planeOffset =
                    std::abs((fromCentre - expectedFromCentre).dot(ringFrame.tangent));
                const double radialOffset = std::abs(fromCentre.norm() - expectedFromCentre.norm());
                deviation.skinned = std::max({deviation.skinned, planeOffset, radialOffset});
                if (fromCentre.norm() > 1e-6 && expectedFromCentre.norm() > 1e-6)
                    deviation.staticPhase =
                        std::max(deviation.staticPhase,
                                 std::acos(std::clamp(
                                     fromCentre.normalized().dot(expectedFromCentre.normalized()),
                                     -1.0, 1.0)));
            }
            continue;
        }
        const std::vector<float> inverseBind = floatAccessor(
            exported,
            exported.json["skins"][static_cast<size_t>(d.skin)]["inverseBindMatrices"].get<int>());
        const std::vector<std::uint32_t>& ring = librarySurface.topology().vertexRing;
        const std::vector<rig::JointPose>& poses = runtime.jointPoses(h);
        for (size_t v = 0; v < ring.size(); ++v) {
            Eigen::Matrix4d ibm;
            for (int k = 0; k < 16; ++k)
                ibm.data()[k] = inverseBind[16 * ring[v] + static_cast<size_t>(k)];
            const Frame& joint = poses[ring[v]].world;
            const Eigen::Vector4d bound =
                ibm * Eigen::Vector4d(bind[3 * v], bind[3 * v + 1], bind[3 * v + 2], 1.0);
            const Vec3 skinned = joint.apply(bound.head<3>());
            const Vec3 expected =
                library.origin() +
                Vec3(local[3 * v], local[3 * v + 1], local[3 * v + 2]).cast<double>();
            deviation.skinned = std::max(deviation.skinned, (skinned - expected).norm());
        }
    }
    return deviation;
}

/// Where the library reference takes a moved object's world frame from:
///  * IndependentFrames: the imported scene (formats::ImportedScene::worldFrame of the project's
///    node with the new local transform) — the library exactly as the editor would run it;
///  * SameFrames: the runtime's node world frame and the descriptor's offset, i.e. bit-identical
///    inputs, so any difference is the runtime's own. The solver is sensitive where a hose is
///    clamped or infeasible, so 1e-16 differences in the inputs can grow; the second variant
///    separates that from errors of the export/runtime pipeline. With independent frames, a
///    hose whose library update was ever Clamped or Infeasible is held to
///    kClampedTolerance instead of kTolerance; with the same frames every hose is exact.
enum class Reference { IndependentFrames, SameFrames };

class RuntimeRoundTrip : public ::testing::TestWithParam<std::tuple<std::string, Reference>>
{
};

TEST_P(RuntimeRoundTrip, RuntimeReproducesTheLibraryAxisAndSurfaceAfterMovesAndGrabs)
{
    const std::string sample = std::get<0>(GetParam());
    const bool sameFrames = std::get<1>(GetParam()) == Reference::SameFrames;
    const fs::path projectFile = projectFileOf(sample);
    if (sample.rfind("engine", 0) == 0 && !haveScenes())
        GTEST_SKIP() << "needs ../shared/scenes (CHAINTUBE_SCENES_DIR)";
    TemporaryFolder folder;
    const fs::path output = folder / (sample + ".glb");
    exportProjectFile(projectFile, output, roots());

    LibraryReference reference = buildReference(projectFile);
    rig::RuntimeLoadReport report;
    rig::HoseRuntime runtime = rig::HoseRuntime::load(output, &report);
    // The library's reference hoses run without a budget: so does the runtime here (the
    // budget's own checks: HoseRuntimeBudget.*).
    runtime.setBudget(UpdateBudget{});
    EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
    ASSERT_EQ(runtime.hoseCount(), static_cast<int>(reference.hoses.size()));
    const GltfDocument exported = readGltf(output);
    attachColliders(reference, exported, runtime, sameFrames);
    EXPECT_EQ(runtime.colliders().size(), reference.colliders.size());

    Deviation worst = compare(runtime, reference, exported);

    // Distinct attachment nodes, as (glTF node, scene id, scene node).
    struct Moved
    {
        int gltfNode;
        std::string scene;
        int sceneNode;
    };
    std::vector<Moved> movable;
    auto addMovable = [&](int node, const std::pair<std::string, int>& sceneNode) {
        bool known = false;
        for (const Moved& m : movable)
            known = known || m.gltfNode == node;
        if (!known && node >= 0) movable.push_back({node, sceneNode.first, sceneNode.second});
    };
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        const size_t hose = static_cast<size_t>(h);
        for (size_t k = 0; k < runtime.description(h).attachments.size(); ++k)
            addMovable(runtime.description(h).attachments[k].node,
                       reference.attachedNodes[hose][k]);
        for (size_t k = 0; k < runtime.description(h).clips.size(); ++k)
            addMovable(runtime.description(h).clips[k].node, reference.clippedNodes[hose][k]);
    }

    // Hoses whose library update was ever Clamped or Infeasible (see Reference).
    std::vector<char> clamped(reference.hoses.size(), 0);
    double worstClamped = 0.0;
    int steps = 0;
    for (int round = 0; round < 3; ++round) {
        // Move up to four scene objects: a translation and a rotation about a tilted axis.
        for (size_t m = 0; m < std::min<size_t>(movable.size(), 4); ++m) {
            const Moved& moved = movable[(m + static_cast<size_t>(round)) % movable.size()];
            rig::NodeTransform local = runtime.node(moved.gltfNode).local;
            local.translation += Vec3(0.01 * (round + 1), -0.006, 0.004 * static_cast<double>(m));
            local.rotation =
                Quat(Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, 1.0, 0.2).normalized())) *
                local.rotation;
            const std::vector<rig::HoseUpdate> updates =
                runtime.setNodeTransform(moved.gltfNode, local);

            formats::ImportedScene& scene = reference.scenes.at(moved.scene);
            scene.nodes[static_cast<size_t>(moved.sceneNode)].localTransform = matrixOf(local);
            // Whether a scene node is the moved one or below it.
            auto underMoved = [&](const std::string& sceneId, int node) {
                for (int n = node; n >= 0;
                     n = reference.scenes.at(sceneId).nodes[static_cast<size_t>(n)].parent)
                    if (sceneId == moved.scene && n == moved.sceneNode) return true;
                return false;
            };
            // Colliders on the moved node or below it follow it.
            std::vector<const MeshCollider*> movedColliders;
            for (size_t c = 0; c < reference.colliders.size(); ++c) {
                const auto& [colliderScene, colliderNode] = reference.colliderNodes[c];
                if (!underMoved(colliderScene, colliderNode)) continue;
                reference.colliders[c]->setFrame(
                    sameFrames ? runtime.nodeWorldFrame(runtime.descriptor().colliders[c])
                               : reference.scenes.at(colliderScene).worldFrame(colliderNode));
                movedColliders.push_back(reference.colliders[c].get());
            }
            for (size_t h = 0; h < reference.hoses.size(); ++h) {
                std::vector<int> ids;
                std::vector<Frame> frames;
                const formats::HoseDefinition& definition = reference.project.hoses[h];
                for (size_t k = 0; k < definition.attachments.size(); ++k) {
                    const auto& [sceneId, node] = reference.attachedNodes[h][k];
                    if (!underMoved(sceneId, node)) continue;
                    Frame offset = definition.attachments[k].offset;
                    offset.rotation.normalize();
                    ids.push_back(reference.hoses[h].attachments()[k].id);
                    if (sameFrames) {
                        const rig::RigAttachment& same =
                            runtime.description(static_cast<int>(h)).attachments[k];
                        frames.push_back(runtime.nodeWorldFrame(same.node) * same.offset);
                    } else {
                        frames.push_back(reference.scenes.at(sceneId).worldFrame(node) * offset);
                    }
                }
                // Clips follow their nodes as attachments do (their ids after the attachments').
                const rig::RigHose& described = runtime.description(static_cast<int>(h));
                for (size_t k = 0; k < definition.clips.size(); ++k) {
                    const auto& [sceneId, node] = reference.clippedNodes[h][k];
                    if (!underMoved(sceneId, node)) continue;
                    ids.push_back(
                        reference.hoses[h].attachments()[definition.attachments.size() + k].id);
                    frames.push_back((sameFrames ? runtime.nodeWorldFrame(described.clips[k].node)
                                                 : reference.scenes.at(sceneId).worldFrame(node)) *
                                     described.clips[k].offset);
                }
                std::optional<UpdateResult> viaLibrary;
                if (ids.size() == 1) {
                    viaLibrary = reference.hoses[h].moveAttachment(ids[0], frames[0]);
                } else if (!ids.empty()) {
                    viaLibrary = reference.hoses[h].moveAttachments(ids, frames);
                } else {
                    bool nearMovedCollider = false;
                    for (const auto& collider : reference.hoses[h].colliders())
                        nearMovedCollider = nearMovedCollider ||
                                            std::find(movedColliders.begin(), movedColliders.end(),
                                                      collider.get()) != movedColliders.end();
                    if (nearMovedCollider) viaLibrary = reference.hoses[h].resolveCollisions();
                }
                // The runtime reports exactly the hoses it updated, with the library's result.
                const auto update =
                    std::find_if(updates.begin(), updates.end(), [&](const rig::HoseUpdate& u) {
                        return u.hose == static_cast<int>(h);
                    });
                ASSERT_EQ(update != updates.end(), viaLibrary.has_value()) << "hose " << h;
                if (viaLibrary) {
                    EXPECT_EQ(update->result.status, viaLibrary->status) << "hose " << h;
                    if (viaLibrary->status != Status::Ok) clamped[h] = 1;
                }
            }
            ++steps;
        }
        // Grab the middle free point of every hose and pull it sideways and up.
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            const std::vector<int>& grabbable = runtime.description(h).grabbablePoints;
            if (grabbable.empty()) continue;
            const int point = grabbable[grabbable.size() / 2];
            const Vec3 target = reference.hoses[static_cast<size_t>(h)].point(point) +
                                Vec3(0.02, 0.03 * (round + 1), -0.01);
            const UpdateResult viaRuntime = runtime.grab(h, point, target);
            const UpdateResult viaLibrary =
                reference.hoses[static_cast<size_t>(h)].grab(point, target);
            EXPECT_EQ(viaRuntime.status, viaLibrary.status);
            if (viaLibrary.status != Status::Ok) clamped[static_cast<size_t>(h)] = 1;
            ++steps;
        }
        runtime.update();
        for (size_t h = 0; h < reference.hoses.size(); ++h) {
            if (reference.hoses[h].spec().gravity.enabled)
                static_cast<void>(reference.hoses[h].step()); // compared below, point by point
            reference.surfaces[h].update(reference.hoses[h]);
        }
        for (int h = 0; h < runtime.hoseCount(); ++h) {
            const Deviation d = compare(runtime, reference, exported, h);
            if (!sameFrames && clamped[static_cast<size_t>(h)]) {
                worstClamped = std::max({worstClamped, d.axis, d.surface, d.skinned});
                continue;
            }
            worst.axis = std::max(worst.axis, d.axis);
            worst.surface = std::max(worst.surface, d.surface);
            worst.skinned = std::max(worst.skinned, d.skinned);
            worst.staticPhase = std::max(worst.staticPhase, d.staticPhase);
        }
    }
    EXPECT_LT(worstClamped, kClampedTolerance);
    EXPECT_GE(steps, 3); // at least one grab per round
    EXPECT_LT(worst.axis, kTolerance);
    EXPECT_LT(worst.surface, kTolerance);
    EXPECT_LT(worst.skinned, kTolerance);
    RecordProperty("axis_error_m", std::to_string(worst.axis));
    RecordProperty("skinned_surface_error_m", std::to_string(worst.skinned));
    if (sameFrames) {
        EXPECT_LT(worst.axis, 1e-12) << "identical inputs must give identical axes";
    }
    std::cout << "[ round trip ] " << sample << (sameFrames ? " (same frames)" : "") << ": "
              << steps << " moves/grabs, axis error " << worst.axis << " m, surface error "
              << worst.surface << " m, skinned-export error " << worst.skinned << " m"
              << (worst.staticPhase > 0 ? ", static meshes' ring phase within " +
                                              std::to_string(worst.staticPhase) + " rad"
                                        : std::string())
              << "; hoses once clamped within " << worstClamped << " m\n";
}

INSTANTIATE_TEST_SUITE_P(
    EverySample, RuntimeRoundTrip,
    ::testing::Combine(::testing::Values("single-hose", "test-rig", "rig-options", "motion-rig",
                                         "engine", "engine-50-hoses"),
                       ::testing::Values(Reference::IndependentFrames, Reference::SameFrames)),
    [](const auto& parameter) {
        std::string name = std::get<0>(parameter.param);
        for (char& c : name)
            if (c == '-') c = '_';
        return name + (std::get<1>(parameter.param) == Reference::SameFrames
                           ? "_same_frames"
                           : "_independent_frames");
    });

TEST(HoseRuntime, AHoseIgnoresTheCollidersItsAttachmentNodesSitInButNotTheirSiblings)
{
    // test-rig with the valve and the floor plate as colliders: left-feed is attached to
    // /test-rig/valve/valve_inlet (a child of the valve), right-return to /test-rig/valve.
    TemporaryFolder folder;
    const fs::path project = samplesDir() / "test-rig.ctproj";
    const formats::Project loaded = loadWithRoots(project);
    const formats::ImportedScenes scenes = formats::importProjectScenes(loaded, project, roots());
    const formats::ImportedScene& rig = scenes.at("rig");
    ExportOptions options;
    options.colliders = {{0, rig.findNode("/test-rig/floor_plate")},
                         {0, rig.findNode("/test-rig/valve")}};
    exportProject(loaded, project, folder / "c.glb", roots(), options);
    rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "c.glb");
    const std::vector<int>& colliderNodes = runtime.descriptor().colliders;
    ASSERT_EQ(colliderNodes.size(), 2u);
    const auto colliderOf = [&](const char* name) {
        for (size_t c = 0; c < colliderNodes.size(); ++c)
            if (colliderNodes[c] == runtime.findNode(name)) return runtime.colliders()[c];
        return std::shared_ptr<MeshCollider>();
    };
    const std::shared_ptr<MeshCollider> valve = colliderOf("valve"),
                                        floor = colliderOf("floor_plate");
    ASSERT_TRUE(valve && floor);
    for (const char* id : {"left-feed", "right-return"}) {
        const int h = runtime.findHose(id);
        ASSERT_GE(h, 0) << id;
        const auto& used = runtime.hose(h).colliders();
        EXPECT_EQ(used.size(), 1u)
            << id << ": the valve is exempt, its sibling the floor plate is not";
        if (!used.empty()) {
            EXPECT_EQ(used[0].get(), floor.get()) << id;
        }
    }

    // Moving the valve carries left-feed's end (in valve_inlet) and right-return's end with it;
    // neither hose is blocked by or pushed out of the valve it sits in.
    const double before = clearance(runtime.hose(runtime.findHose("left-feed")), *valve).distance;
    const int valveNode = runtime.findNode("valve");
    rig::NodeTransform local = runtime.node(valveNode).local;
    local.translation += Vec3(0.0, 0.02, 0.01);
    const std::vector<rig::HoseUpdate> updates = runtime.setNodeTransform(valveNode, local);
    EXPECT_EQ(updates.size(), 2u);
    for (const rig::HoseUpdate& update : updates)
        EXPECT_EQ(update.result.status, Status::Ok) << runtime.description(update.hose).id;
    const double after = clearance(runtime.hose(runtime.findHose("left-feed")), *valve).distance;
    std::cout << "[ exemption ] left-feed surface to the valve: " << before << " m, after moving "
              << "the valve " << after << " m\n";
}

/// The test rig sample exported to `folder`/rig.glb and loaded by the runtime.
rig::HoseRuntime exportedTestRig(const TemporaryFolder& folder)
{
    const fs::path output = folder / "rig.glb";
    exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
    return rig::HoseRuntime::load(output);
}

TEST(HoseRuntime, JointLocalPosesUnderAMovedNodeStayConsistentWithTheirWorldPoses)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = exportedTestRig(folder);
    const int valve = runtime.findNode("valve");
    ASSERT_GE(valve, 0);
    rig::NodeTransform local = runtime.node(valve).local;
    local.translation += Vec3(0.0, 0.05, 0.02);
    const auto updates = runtime.setNodeTransform(valve, local);
    EXPECT_FALSE(updates.empty()); // both hoses end at the valve (one through valve_inlet)
    runtime.update();
    for (int h = 0; h < runtime.hoseCount(); ++h)
        for (const rig::JointPose& pose : runtime.jointPoses(h)) {
            const int parent = runtime.node(pose.node).parent;
            const Frame parentWorld = runtime.nodeWorldFrame(parent);
            const Vec3 recomposed = parentWorld.apply(pose.local.translation);
            EXPECT_LT((recomposed - pose.world.translation).norm(), 1e-9);
        }
}

/// World ← node of a runtime node, composed from the local transforms up to the root.
formats::Mat4 worldMatrixOf(const rig::HoseRuntime& runtime, int node)
{
    formats::Mat4 world = formats::Mat4::Identity();
    for (; node >= 0; node = runtime.node(node).parent)
        world = matrixOf(runtime.node(node).local) * world;
    return world;
}

TEST(HoseRuntime, JointLocalPosesComposeToTheirWorldPosesUnderScaledParents)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = exportedTestRig(folder);
    const int hose = runtime.findHose("left-feed");
    ASSERT_GE(hose, 0);
    runtime.update();
    ASSERT_FALSE(runtime.jointPoses(hose).empty());
    // The parent most of the hose's joints share.
    std::map<int, int> sharing;
    for (const rig::JointPose& pose : runtime.jointPoses(hose))
        ++sharing[runtime.node(pose.node).parent];
    const int parent = std::max_element(sharing.begin(), sharing.end(), [](auto a, auto b) {
                           return a.second < b.second;
                       })->first;
    ASSERT_GE(parent, 0);
    // That parent turned and scaled: uniformly (the joints' local poses by
    // quaternion products), uniformly with a reflection and non-uniformly (through the matrix and
    // its decomposition). Parent world · local = world for each joint under that parent; under a
    // non-uniform scale a turned joint's exact local transform has shear, which a
    // translation-rotation-scale cannot hold: there its translation alone is exact.
    const rig::NodeTransform original = runtime.node(parent).local;
    for (const Vec3& scale : {Vec3(2.0, 2.0, 2.0), Vec3(-1.5, 1.5, 1.5), Vec3(1.0, 2.0, 0.5)}) {
        SCOPED_TRACE(::testing::Message() << "parent scale " << scale.transpose());
        const bool uniform = scale.cwiseAbs().maxCoeff() == scale.cwiseAbs().minCoeff();
        rig::NodeTransform local = original;
        local.scale = scale;
        local.rotation = Quat(Eigen::AngleAxisd(0.3, Vec3(1.0, 2.0, 3.0).normalized()));
        static_cast<void>(runtime.setNodeTransform(parent, local));
        runtime.update();
        const formats::Mat4 parentWorld = worldMatrixOf(runtime, parent);
        int checked = 0;
        for (const rig::JointPose& pose : runtime.jointPoses(hose)) {
            if (runtime.node(pose.node).parent != parent) continue;
            rig::NodeTransform world;
            world.translation = pose.world.translation;
            world.rotation = pose.world.rotation;
            const formats::Mat4 composed = parentWorld * matrixOf(pose.local);
            const formats::Mat4 expected = matrixOf(world);
            EXPECT_LT((composed.col(3) - expected.col(3)).norm(), 1e-9);
            if (uniform) {
                EXPECT_LT((composed - expected).cwiseAbs().maxCoeff(), 1e-9);
            }
            ++checked;
        }
        EXPECT_GT(checked, 10);
    }
}

TEST(HoseRuntime, AppliesGravityTorsionAndCollidersFromTheDescriptor)
{
    TemporaryFolder folder;
    const fs::path output = folder / "options.glb";
    exportProjectFile(testDataDir() / "rig-options.ctproj", output, roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(output);
    const int tail = runtime.findHose("valve-tail");
    const int loop = runtime.findHose("bracket-loop");
    const int pipe = runtime.findHose("pipe-on-plate");
    ASSERT_GE(tail, 0);
    ASSERT_GE(loop, 0);
    ASSERT_GE(pipe, 0);
    EXPECT_TRUE(runtime.hose(tail).spec().gravity.enabled);
    EXPECT_TRUE(runtime.hose(loop).spec().torsion.enabled);
    EXPECT_EQ(runtime.hose(loop).spec().torsion.twistLimit, 0.2);
    ASSERT_EQ(runtime.colliders().size(), 2u); // floor_plate and valve
    // The tail is attached to the valve: it collides with the floor plate only; the loop with
    // both; the static pipe lies on the plate (attached to it): only the valve.
    EXPECT_EQ(runtime.hose(tail).colliders().size(), 1u);
    EXPECT_EQ(runtime.hose(loop).colliders().size(), 2u);
    EXPECT_EQ(runtime.hose(pipe).colliders().size(), 1u);

    // Gravity: the tail was exported as it hangs (below its route) and starts at rest: updates
    // without input leave it exactly as loaded.
    const int end = runtime.hose(tail).pointCount() - 1;
    const std::vector<Vec3> loaded = runtime.hose(tail).points();
    {
        const formats::Project project = loadWithRoots(testDataDir() / "rig-options.ctproj");
        const formats::ImportedScenes scenes =
            formats::importProjectScenes(project, testDataDir() / "rig-options.ctproj", roots());
        const auto definition =
            std::find_if(project.hoses.begin(), project.hoses.end(),
                         [](const formats::HoseDefinition& d) { return d.id == "valve-tail"; });
        ASSERT_NE(definition, project.hoses.end());
        const Hose route = formats::buildHose(project, *definition, scenes);
        EXPECT_LT(loaded.back().y(), route.points().back().y() - 0.01)
            << "exported along its route, not hanging";
        Hose settled = route;
        EXPECT_GT(formats::settleUnderGravity(settled, *definition, project, scenes), 0);
        for (size_t i = 0; i < loaded.size(); ++i)
            EXPECT_LT((loaded[i] - settled.points()[i]).norm(), 1e-9) << i;
    }
    for (int frame = 0; frame < 30; ++frame)
        runtime.update();
    EXPECT_EQ(runtime.hose(tail).points(), loaded);
    // An input wakes it: lift the middle 3 cm and hold it there; the free end then sinks.
    const int middle = runtime.hose(tail).pointCount() / 2;
    ASSERT_NE(
        runtime.grab(tail, middle, runtime.hose(tail).point(middle) + Vec3(0.0, 0.03, 0.0)).status,
        Status::InvalidInput);
    const double before = runtime.hose(tail).point(end).y();
    for (int frame = 0; frame < 30; ++frame)
        runtime.update();
    EXPECT_LT(runtime.hose(tail).point(end).y(), before - 1e-3);
    // The plate is a collider of the tail: its surface is not inside the plate by more than
    // the collision tolerance (CollisionOptions::tolerance, 1e-4 m; 1e-6 m of slack).
    const Clearance toPlate = clearance(runtime.hose(tail), *runtime.colliders()[0]);
    ASSERT_TRUE(toPlate.found);
    EXPECT_GT(toPlate.distance, -1e-4 - 1e-6);
    std::cout << "[ options ] valve-tail: free end sank "
              << before - runtime.hose(tail).point(end).y()
              << " m in 30 updates; clearance to the floor plate " << toPlate.distance << " m\n";
}

TEST(HoseRuntime, RejectsGrabsOfFixedPointsAndUnknownNodes)
{
    TemporaryFolder folder;
    rig::HoseRuntime runtime = exportedTestRig(folder);
    const Vec3 before = runtime.hose(0).point(0);
    EXPECT_EQ(runtime.grab(0, 0, Vec3(1, 1, 1)).status, Status::InvalidInput); // attached
    EXPECT_EQ(runtime.grab(5, 3, Vec3(1, 1, 1)).status, Status::InvalidInput); // no hose 5
    EXPECT_EQ(runtime.setNodeTransform(10000, {}).front().result.status, Status::InvalidInput);
    rig::NodeTransform nan;
    nan.translation.x() = std::nan("");
    EXPECT_EQ(runtime.setNodeTransform(1, nan).front().result.status, Status::InvalidInput);
    EXPECT_EQ(runtime.hose(0).point(0), before);
}

TEST(HoseRuntime, FallsBackToTheSidecarDescriptorWhenTheExtensionWasStripped)
{
    TemporaryFolder folder;
    const fs::path output = folder / "rig.gltf";
    exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
    Json gltf = Json::parse(readBytes(output));
    gltf.erase("extensions"); // what gltf-transform does with unknown extensions
    writeBytes(output, gltf.dump());
    rig::RuntimeLoadReport report;
    const rig::HoseRuntime runtime = rig::HoseRuntime::load(output, &report);
    EXPECT_EQ(runtime.hoseCount(), 2);
    EXPECT_EQ(report.descriptorSource, (folder / "rig.hoses.json").string());
    ASSERT_EQ(report.warnings.size(), 1u);

    fs::remove(folder / "rig.hoses.json");
    try {
        rig::HoseRuntime::load(output);
        FAIL() << "loaded without any descriptor";
    } catch (const Error& error) {
        EXPECT_NE(std::string(error.what()).find("rig.gltf"), std::string::npos) << error.what();
    }
}

} // namespace
} // namespace chaintube::exporting::testing
