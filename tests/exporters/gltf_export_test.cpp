// The glTF hose rig as written: structure the spec and our descriptor promise, atomic writes.
#include "export_test_support.h"

#include <chaintube/export/inspect.h>
#include <chaintube/export/rig_descriptor.h>
#include <chaintube/formats/errors.h>
#include <map>
#include <set>

namespace chaintube::exporting::testing {
namespace {

ExportReport exportSample(const std::string& sample, const fs::path& output,
                          const ExportOptions& options = {})
{
    return exportProjectFile(samplesDir() / (sample + ".ctproj"), output, roots(), options);
}

TEST(GltfExport, EveryHoseIsASkinnedMeshAtTheSceneRootWithOneTrsJointPerAxisPoint)
{
    TemporaryFolder folder;
    for (const std::string& sample : availableSamples()) {
        const fs::path output = folder / (sample + ".glb");
        const ExportReport report = exportSample(sample, output);
        const GltfDocument gltf = readGltf(output);
        const Json& descriptor = gltf.json["extensions"][rig::kExtensionName];
        ASSERT_EQ(descriptor["hoses"].size(), static_cast<size_t>(report.hoseCount)) << sample;
        const std::vector<int> sceneRoots = gltf.json["scenes"][0]["nodes"].get<std::vector<int>>();
        for (const Json& hose : descriptor["hoses"]) {
            const int mesh = hose["mesh"].get<int>();
            EXPECT_NE(std::find(sceneRoots.begin(), sceneRoots.end(), mesh), sceneRoots.end())
                << sample << ": skinned mesh node not at the scene root";
            const Json& node = gltf.json["nodes"][static_cast<size_t>(mesh)];
            ASSERT_EQ(node["skin"].get<int>(), hose["skin"].get<int>());
            const Json& skin = gltf.json["skins"][hose["skin"].get<size_t>()];
            EXPECT_EQ(skin["joints"], hose["joints"]);
            EXPECT_EQ(skin["joints"].size(), hose["axis"].size()) << "one joint per axis point";
            for (const Json& joint : skin["joints"])
                EXPECT_FALSE(gltf.json["nodes"][joint.get<size_t>()].contains("matrix"))
                    << sample << ": joint " << joint << " uses matrix";
            const Json& attributes =
                gltf.json["meshes"][node["mesh"].get<size_t>()]["primitives"][0]["attributes"];
            EXPECT_TRUE(attributes.contains("JOINTS_0") && attributes.contains("WEIGHTS_0"));
            // Rigid weights: (1, 0, 0, 0) for every vertex.
            const std::vector<float> weights =
                floatAccessor(gltf, attributes["WEIGHTS_0"].get<int>());
            for (size_t v = 0; v < weights.size(); v += 4) {
                ASSERT_EQ(weights[v], 1.0f);
                ASSERT_EQ(weights[v + 1] + weights[v + 2] + weights[v + 3], 0.0f);
            }
        }
    }
}

TEST(GltfExport, TheExtensionIsUsedButNeverRequired)
{
    TemporaryFolder folder;
    exportSample("test-rig", folder / "rig.glb");
    const Json json = readGltf(folder / "rig.glb").json;
    EXPECT_EQ(json["extensionsUsed"], Json::array({rig::kExtensionName}));
    EXPECT_FALSE(json.contains("extensionsRequired"));
}

TEST(GltfExport, EmptyDescriptorListsAreWrittenAsArraysNotNull)
{
    // single-hose has no attachments: tinygltf would have written "attachments": null.
    TemporaryFolder folder;
    exportSample("single-hose", folder / "free.glb");
    const Json embedded = readGltf(folder / "free.glb").json["extensions"][rig::kExtensionName];
    const Json sidecar = Json::parse(readBytes(folder / "free.hoses.json"));
    for (const Json* descriptor : {&embedded, &sidecar}) {
        const Json& attachments = (*descriptor)["hoses"][0]["attachments"];
        EXPECT_TRUE(attachments.is_array()) << attachments.dump();
        EXPECT_TRUE(attachments.empty());
    }
    EXPECT_EQ(embedded, sidecar);
}

TEST(GltfExport, AttachedJointsAreChildrenOfTheirSceneNodeAndFreeJointsHangUnderTheRigNode)
{
    TemporaryFolder folder;
    exportSample("test-rig", folder / "rig.glb");
    const Json json = readGltf(folder / "rig.glb").json;
    const Json& hose =
        json["extensions"][rig::kExtensionName]["hoses"][0]; // left-feed: 0–1 on bracket_left
    const Json& attachment = hose["attachments"][0];
    const Json& bracket = json["nodes"][attachment["node"].get<size_t>()];
    EXPECT_EQ(bracket["name"], "bracket_left");
    const std::vector<int> children = bracket["children"].get<std::vector<int>>();
    for (int point : {0, 1})
        EXPECT_NE(std::find(children.begin(), children.end(), hose["joints"][point].get<int>()),
                  children.end());
    const std::vector<int> rigChildren =
        json["nodes"][hose["rig"].get<size_t>()]["children"].get<std::vector<int>>();
    EXPECT_NE(std::find(rigChildren.begin(), rigChildren.end(), hose["joints"][8].get<int>()),
              rigChildren.end());
}

TEST(GltfExport, JointsAtRootGiveEveryHoseItsOwnJointTree)
{
    TemporaryFolder folder;
    ExportOptions options;
    options.jointsUnderAttachedNodes = false;
    exportSample("test-rig", folder / "rig.glb", options);
    const Json json = readGltf(folder / "rig.glb").json;
    for (const Json& hose : json["extensions"][rig::kExtensionName]["hoses"]) {
        const std::vector<int> rigChildren =
            json["nodes"][hose["rig"].get<size_t>()]["children"].get<std::vector<int>>();
        EXPECT_EQ(rigChildren, hose["joints"].get<std::vector<int>>());
    }
}

TEST(GltfExport, SplitGltfWritesJsonBinAndDescriptorThatReferToEachOther)
{
    TemporaryFolder folder;
    const ExportReport report = exportSample("test-rig", folder / "rig.gltf");
    EXPECT_EQ(report.binFile, folder / "rig.bin");
    const Json json = Json::parse(readBytes(folder / "rig.gltf"));
    EXPECT_EQ(json["buffers"][0]["uri"], "rig.bin");
    EXPECT_EQ(json["buffers"][0]["byteLength"].get<size_t>(), fs::file_size(folder / "rig.bin"));
    EXPECT_TRUE(fs::exists(folder / "rig.hoses.json"));
}

TEST(GltfExport, TheSameProjectExportsToTheSameBytes)
{
    TemporaryFolder folder;
    exportSample("test-rig", folder / "a.glb");
    exportSample("test-rig", folder / "b.glb");
    EXPECT_EQ(readBytes(folder / "a.glb"), readBytes(folder / "b.glb"));
}

TEST(GltfExport, AFailedWriteLeavesNoHalfOutput)
{
    TemporaryFolder folder;
    // The descriptor's name is taken by a folder: the .bin is written first, then the
    // descriptor fails; the .bin this call created must be gone and no .gltf written.
    fs::create_directories(folder / "rig.hoses.json");
    EXPECT_THROW(exportSample("test-rig", folder / "rig.gltf"), formats::FileError);
    EXPECT_FALSE(fs::exists(folder / "rig.bin"));
    EXPECT_FALSE(fs::exists(folder / "rig.gltf"));
}

TEST(GltfExport, AFailedReExportLeavesThePreviousExportUntouched)
{
    TemporaryFolder folder;
    exportSample("test-rig", folder / "rig.glb", {});
    const std::string before = readBytes(folder / "rig.glb");
    fs::remove(folder / "rig.hoses.json");
    fs::create_directories(folder / "rig.hoses.json"); // the sidecar is written before the GLB
    ExportOptions moved;
    moved.jointsUnderAttachedNodes = false; // different contents, so a write would show
    EXPECT_THROW(exportSample("test-rig", folder / "rig.glb", moved), formats::FileError);
    EXPECT_EQ(readBytes(folder / "rig.glb"), before);
}

TEST(GltfExport, CancellingFromTheProgressCallbackWritesNothing)
{
    TemporaryFolder folder;
    ExportOptions options;
    std::vector<double> seen;
    options.progress = [&](double fraction) {
        seen.push_back(fraction);
        return fraction < 0.7;
    };
    EXPECT_THROW(exportSample("test-rig", folder / "rig.glb", options), formats::Cancelled);
    EXPECT_FALSE(fs::exists(folder / "rig.glb"));
    EXPECT_FALSE(fs::exists(folder / "rig.hoses.json"));
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
}

TEST(GltfExport, ProgressRunsFromZeroToOne)
{
    TemporaryFolder folder;
    ExportOptions options;
    std::vector<double> seen;
    options.progress = [&](double fraction) {
        seen.push_back(fraction);
        return true;
    };
    exportSample("test-rig", folder / "rig.glb", options);
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_DOUBLE_EQ(seen.back(), 1.0);
}

// Building the hoses (where a gravity hose settles, up to 3,000 steps) reports progress once
// per hose between import (to 55 %) and export (from 60 %), and can be cancelled there.
TEST(GltfExport, ProgressAdvancesOncePerHoseWhileTheHosesAreBuilt)
{
    TemporaryFolder folder;
    const fs::path projectFile = testDataDir() / "rig-options.ctproj";
    const formats::Project project = loadWithRoots(projectFile);
    ASSERT_GE(project.hoses.size(), 2u);
    std::vector<double> seen;
    ExportOptions options;
    options.progress = [&](double fraction) {
        seen.push_back(fraction);
        return true;
    };
    exportProject(project, projectFile, folder.path() / "rig.glb", roots(), options);
    std::vector<double> building;
    for (double f : seen)
        if (f > 0.55 && f <= 0.6) building.push_back(f);
    ASSERT_EQ(building.size(), project.hoses.size()) << ::testing::PrintToString(building);
    EXPECT_DOUBLE_EQ(building.back(), 0.6);
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));

    options.progress = [&](double fraction) { return !(fraction > 0.55 && fraction <= 0.6); };
    EXPECT_THROW(
        exportProject(project, projectFile, folder.path() / "cancelled.glb", roots(), options),
        formats::Cancelled);
    EXPECT_FALSE(fs::exists(folder.path() / "cancelled.glb"));
}

TEST(GltfExport, AProjectWhoseSceneRootIsUnknownFailsNamingTheProjectAndThePath)
{
    TemporaryFolder folder;
    try {
        exportProjectFile(samplesDir() / "engine.ctproj", folder / "engine.glb", {});
        FAIL() << "exported without the scenes root";
    } catch (const formats::FileError& error) {
        const std::string what = error.what();
        EXPECT_NE(what.find("engine.ctproj"), std::string::npos) << what;
        EXPECT_NE(what.find("scenes:2CylinderEngine.glb"), std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(folder / "engine.glb"));
}

TEST(GltfExport, RejectsAnOutputThatIsNeitherGlbNorGltf)
{
    TemporaryFolder folder;
    try {
        exportSample("single-hose", folder / "out.obj");
        FAIL();
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("out.obj"), std::string::npos);
    }
}

/// Index of the hose with this id in an exported descriptor.
size_t hoseIndex(const Json& json, const std::string& id)
{
    const Json& hoses = json["extensions"][rig::kExtensionName]["hoses"];
    for (size_t h = 0; h < hoses.size(); ++h)
        if (hoses[h]["id"] == id) return h;
    ADD_FAILURE() << "no hose " << id;
    return 0;
}

/// World matrix of a glTF node (TRS or matrix), parents first.
Eigen::Matrix4d worldOf(const Json& json, int node)
{
    std::map<int, int> parent;
    for (size_t i = 0; i < json["nodes"].size(); ++i)
        for (const Json& child : json["nodes"][i].value("children", Json::array()))
            parent[child.get<int>()] = static_cast<int>(i);
    Eigen::Matrix4d world = Eigen::Matrix4d::Identity();
    for (int n = node; n >= 0; n = parent.count(n) ? parent[n] : -1) {
        const Json& j = json["nodes"][static_cast<size_t>(n)];
        Eigen::Matrix4d local = Eigen::Matrix4d::Identity();
        if (j.contains("matrix")) {
            for (int k = 0; k < 16; ++k)
                local.data()[k] = j["matrix"][static_cast<size_t>(k)].get<double>();
        } else {
            const std::vector<double> t = j.value("translation", std::vector<double>{0, 0, 0});
            const std::vector<double> r = j.value("rotation", std::vector<double>{0, 0, 0, 1});
            const std::vector<double> sc = j.value("scale", std::vector<double>{1, 1, 1});
            local.block<3, 3>(0, 0) =
                Eigen::Quaterniond(r[3], r[0], r[1], r[2]).toRotationMatrix() *
                Eigen::Vector3d(sc[0], sc[1], sc[2]).asDiagonal();
            local.block<3, 1>(0, 3) = Eigen::Vector3d(t[0], t[1], t[2]);
        }
        world = local * world;
    }
    return world;
}

TEST(GltfExport, AStaticHoseIsAPlainMeshUnderItsNodeWhereTheSkinnedHoseWouldBe)
{
    TemporaryFolder folder;
    const fs::path project = testDataDir() / "rig-options.ctproj";
    exportProjectFile(project, folder / "plain.glb", roots());
    ExportOptions skinnedOptions;
    skinnedOptions.plainMeshesForStaticHoses = false;
    exportProjectFile(project, folder / "skinned.glb", roots(), skinnedOptions);
    const GltfDocument plain = readGltf(folder / "plain.glb");
    const GltfDocument skinned = readGltf(folder / "skinned.glb");

    const size_t h = hoseIndex(plain.json, "pipe-on-plate");
    const Json& hose = plain.json["extensions"][rig::kExtensionName]["hoses"][h];
    EXPECT_EQ(hose["static"], true);
    EXPECT_EQ(hose["skin"], -1);
    EXPECT_EQ(hose["rig"], -1);
    EXPECT_TRUE(hose["joints"].empty());
    EXPECT_TRUE(hose["grabbablePoints"].empty());
    const int meshNode = hose["mesh"].get<int>();
    const Json& node = plain.json["nodes"][static_cast<size_t>(meshNode)];
    EXPECT_FALSE(node.contains("skin"));
    const Json& plate = plain.json["nodes"][hose["attachments"][0]["node"].get<size_t>()];
    EXPECT_EQ(plate["name"], "floor_plate");
    const std::vector<int> plateChildren = plate["children"].get<std::vector<int>>();
    EXPECT_NE(std::find(plateChildren.begin(), plateChildren.end(), meshNode), plateChildren.end());
    // The only hoses that are skinned are the other two.
    for (const Json& other : plain.json["extensions"][rig::kExtensionName]["hoses"])
        EXPECT_EQ(other["static"], other["id"] == "pipe-on-plate") << other["id"];

    // Same place as the skinned export's bind pose (world metres), vertex for vertex.
    const Json& skinnedHose = skinned.json["extensions"][rig::kExtensionName]["hoses"]
                                          [hoseIndex(skinned.json, "pipe-on-plate")];
    EXPECT_EQ(skinnedHose["static"], false);
    const auto positionsOf = [](const GltfDocument& document, int nodeIndex) {
        const Json& n = document.json["nodes"][static_cast<size_t>(nodeIndex)];
        return floatAccessor(
            document,
            document
                .json["meshes"][n["mesh"].get<size_t>()]["primitives"][0]["attributes"]["POSITION"]
                .get<int>());
    };
    const std::vector<float> local = positionsOf(plain, meshNode);
    const std::vector<float> world = positionsOf(skinned, skinnedHose["mesh"].get<int>());
    ASSERT_EQ(local.size(), world.size());
    const Eigen::Matrix4d placement = worldOf(plain.json, meshNode);
    double worst = 0.0;
    for (size_t v = 0; v < local.size() / 3; ++v) {
        const Eigen::Vector4d p =
            placement * Eigen::Vector4d(local[3 * v], local[3 * v + 1], local[3 * v + 2], 1.0);
        worst = std::max(
            worst, (p.head<3>() - Eigen::Vector3d(world[3 * v], world[3 * v + 1], world[3 * v + 2]))
                       .norm());
    }
    EXPECT_LT(worst, 1e-6);
    EXPECT_TRUE(validateFile(folder / "plain.glb", roots()).valid());
}

TEST(GltfExport, AHoseFixedToOneNodeHasAllItsJointsUnderItsOwnRigNodeBelowThatNode)
{
    TemporaryFolder folder;
    exportProjectFile(testDataDir() / "rig-options.ctproj", folder / "rig.glb", roots());
    const Json json = readGltf(folder / "rig.glb").json;
    const Json& hose =
        json["extensions"][rig::kExtensionName]["hoses"][hoseIndex(json, "valve-tail")];
    const Json& rigNode = json["nodes"][hose["rig"].get<size_t>()];
    EXPECT_EQ(rigNode["children"], hose["joints"]) << "every joint, attached or free";
    const Json& valve = json["nodes"][hose["attachments"][0]["node"].get<size_t>()];
    EXPECT_EQ(valve["name"], "valve");
    const std::vector<int> valveChildren = valve["children"].get<std::vector<int>>();
    EXPECT_NE(std::find(valveChildren.begin(), valveChildren.end(), hose["rig"].get<int>()),
              valveChildren.end());
    // The joints are still where the hose is (world), e.g. the first one at axis point 0.
    const Eigen::Matrix4d first = worldOf(json, hose["joints"][0].get<int>());
    const std::vector<double> axis0 = hose["axis"][0].get<std::vector<double>>();
    EXPECT_LT((first.block<3, 1>(0, 3) - Eigen::Vector3d(axis0[0], axis0[1], axis0[2])).norm(),
              1e-9);
}

TEST(GltfExport, AHoseFixedWhollyToTheWorldIsAPlainMeshUnderTheRootNode)
{
    TemporaryFolder folder;
    HoseSpec spec;
    spec.segmentCount = 6;
    ExportHose input{
        "pinned", "", Hose::alongRoute({{0, 1, 0}, {0.5, 1, 0}}, spec), {}, {0.2, 0.2, 0.2, 1.0},
        0.5};
    input.hose.attach(0, 6, Frame::identity());
    input.attachedNodes.push_back({});
    const ExportReport report = exportRig({}, {input}, "world", folder / "w.glb");
    ASSERT_EQ(report.descriptor.hoses.size(), 1u);
    const rig::RigHose& hose = report.descriptor.hoses[0];
    EXPECT_TRUE(hose.isStatic);
    EXPECT_EQ(report.jointCount, 0);
    const Json json = readGltf(folder / "w.glb").json;
    EXPECT_EQ(json["nodes"][0]["children"], Json::array({hose.meshNode}));
    EXPECT_FALSE(json.contains("skins"));
    const ValidationResult validation = validateFile(folder / "w.glb", roots());
    EXPECT_TRUE(validation.valid()) << (validation.errors.empty() ? "" : validation.errors.front());
}

TEST(GltfExport, ColliderNodesAreListedInTheDescriptorAndKeepTheirMeshesWithoutTheScene)
{
    TemporaryFolder folder;
    const fs::path project = samplesDir() / "test-rig.ctproj";
    formats::Project loaded = loadWithRoots(project);
    loaded.exportSettings.includeScene = false;
    const formats::ImportedScenes scenes = formats::importProjectScenes(loaded, project, roots());
    const formats::ImportedScene& rig = scenes.at("rig");
    ExportOptions options;
    options.colliders = {{0, rig.findNode("/test-rig/floor_plate")},
                         {0, rig.findNode("/test-rig/valve")}};
    const ExportReport report = exportProject(loaded, project, folder / "c.glb", roots(), options);
    const Json json = readGltf(folder / "c.glb").json;
    const std::vector<int> colliders = report.descriptor.colliders;
    ASSERT_EQ(colliders.size(), 2u);
    EXPECT_LT(colliders[0], colliders[1]);
    std::set<std::string> names;
    for (int node : colliders) {
        names.insert(json["nodes"][static_cast<size_t>(node)]["name"].get<std::string>());
        EXPECT_TRUE(json["nodes"][static_cast<size_t>(node)].contains("mesh")) << node;
    }
    EXPECT_EQ(names, (std::set<std::string>{"floor_plate", "valve"}));
    EXPECT_EQ(json["extensions"][rig::kExtensionName]["colliders"], Json(colliders));
    // Without the scene, the other parts (the brackets) carry no mesh.
    for (const Json& node : json["nodes"]) {
        if (node.value("name", "") == "bracket_left") {
            EXPECT_FALSE(node.contains("mesh"));
        }
    }

    options.colliders = {{0, rig.findNode("/test-rig/valve/valve_inlet")}};
    try {
        exportProject(loaded, project, folder / "d.glb", roots(), options);
        FAIL() << "a collider without a mesh was accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("/test-rig/valve/valve_inlet"), std::string::npos)
            << error.what();
    }
    EXPECT_FALSE(fs::exists(folder / "d.glb"));
}

TEST(GltfExport, TheFiftyHoseEngineExportsEveryHoseWithItsJoints)
{
    if (!haveScenes()) GTEST_SKIP() << "needs ../shared/scenes";
    TemporaryFolder folder;
    const ExportReport report = exportSample("engine-50-hoses", folder / "engine.glb");
    EXPECT_EQ(report.hoseCount, 50);
    EXPECT_EQ(report.descriptor.hoses.size(), 50u);
    int joints = 0;
    for (const rig::RigHose& hose : report.descriptor.hoses)
        joints += static_cast<int>(hose.jointNodes.size());
    EXPECT_EQ(report.jointCount, joints);
    // A measurement for the log, not an assertion (timings: tests/bench/PERFORMANCE-NOTES.md).
    std::cout << "[ timing ] engine-50-hoses: import + build + export " << report.seconds << " s, "
              << report.bytesWritten / 1024 << " KiB, " << report.jointCount << " joints\n";
}

} // namespace
} // namespace chaintube::exporting::testing
