// importScene() on the third-party scenes in CHAINTUBE_SCENES_DIR (skipped when absent).
#include "chaintube/formats/scene_import.h"

#include <filesystem>
#include <gtest/gtest.h>

namespace chaintube::formats {
namespace {

std::filesystem::path sceneFile(const char* name)
{
    return std::filesystem::path(CHAINTUBE_SCENES_DIR) / name;
}

#define SKIP_UNLESS_PRESENT(file)                                                                  \
    if (!std::filesystem::exists(file))                                                            \
    GTEST_SKIP() << "third-party scene " << (file)                                                 \
                 << " is absent (set CHAINTUBE_SCENES_DIR to the folder holding it)"

std::vector<std::string> childNames(const ImportedScene& scene, int node)
{
    std::vector<std::string> names;
    for (int child : scene.nodes[size_t(node)].children)
        names.push_back(scene.nodes[size_t(child)].name);
    return names;
}

TEST(RealScenes, StepAssemblyComesThroughAsNamedProductStructure)
{
    const auto file = sceneFile("as1-oc-214.stp");
    SKIP_UNLESS_PRESENT(file);
    const ImportedScene scene = importScene(file);

    EXPECT_EQ(scene.format, "STEP");
    EXPECT_EQ(scene.nodes[0].path, "/as1");
    EXPECT_EQ(childNames(scene, 0),
              (std::vector<std::string>{"rod-assembly_1", "l-bracket-assembly_1", "plate_1",
                                        "l-bracket-assembly_2"}));
    const int rod = scene.findNode("/as1/rod-assembly_1");
    ASSERT_GE(rod, 0);
    EXPECT_EQ(childNames(scene, rod), (std::vector<std::string>{"nut_1", "nut_2", "rod_1"}));
    const int bracket = scene.findNode("/as1/l-bracket-assembly_1");
    EXPECT_EQ(childNames(scene, bracket),
              (std::vector<std::string>{"nut-bolt-assembly_1", "nut-bolt-assembly_2",
                                        "nut-bolt-assembly_3", "l-bracket_1"}));
    EXPECT_GE(scene.findNode("/as1/l-bracket-assembly_2/nut-bolt-assembly_3/bolt_1"), 0);

    // The file states millimetres; the plate lies in the source XY plane (Z up), so after
    // conversion it spans metres in X and Z and is thin in Y.
    EXPECT_EQ(scene.sourceUnits.unitSource, UnitSource::FileHeader);
    EXPECT_DOUBLE_EQ(scene.sourceUnits.metresPerUnit, 0.001);
    const int plate = scene.findNode("/as1/plate_1");
    ASSERT_GE(plate, 0);
    ASSERT_EQ(scene.nodes[size_t(plate)].meshes.size(), 1u);
    const SceneMesh& mesh = scene.meshes[size_t(scene.nodes[size_t(plate)].meshes[0])];
    const Mat4 world = scene.worldTransform(plate);
    Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9), high = -low;
    for (size_t i = 0; i < mesh.positions.size(); i += 3) {
        const Eigen::Vector4d p(mesh.positions[i], mesh.positions[i + 1], mesh.positions[i + 2], 1);
        const Eigen::Vector3d w = (world * p).head<3>();
        low = low.cwiseMin(w);
        high = high.cwiseMax(w);
    }
    const Eigen::Vector3d size = high - low;
    EXPECT_GT(size.x(), 0.05);
    EXPECT_LT(size.x(), 1.0);
    EXPECT_GT(size.z(), 0.05);
    EXPECT_LT(size.y(), 0.5 * std::min(size.x(), size.z()));

    // 0.1 mm chordal tolerance: STACK-NOTES measured 5,180 triangles.
    EXPECT_EQ(scene.instancedTriangleCount(), 5180u);
}

TEST(RealScenes, StepChordalToleranceControlsTessellationDensity)
{
    const auto file = sceneFile("as1-oc-214.stp");
    SKIP_UNLESS_PRESENT(file);
    ImportOptions coarse;
    coarse.chordalTolerance = 2e-3;
    ImportOptions fine;
    fine.chordalTolerance = 2e-5;
    fine.angularTolerance = 0.2;
    EXPECT_LT(importScene(file, coarse).meshTriangleCount(),
              importScene(file, fine).meshTriangleCount());
}

TEST(RealScenes, StepImportCanBeCancelled)
{
    const auto file = sceneFile("as1-oc-214.stp");
    SKIP_UNLESS_PRESENT(file);
    ImportOptions options;
    options.progress = [](double fraction) { return fraction < 0.3; };
    EXPECT_THROW(importScene(file, options), Cancelled);
}

TEST(RealScenes, EngineGlbKeepsItsHierarchyWithStableGeneratedNames)
{
    const auto file = sceneFile("2CylinderEngine.glb");
    SKIP_UNLESS_PRESENT(file);
    const ImportedScene scene = importScene(file);
    // 82 glTF nodes under assimp's synthetic ROOT (two scene roots: camera and engine).
    EXPECT_EQ(scene.nodes.size(), 83u);
    EXPECT_EQ(scene.nodes[0].path, "/ROOT");
    EXPECT_EQ(scene.sourceUnits.unitSource, UnitSource::FormatConvention);
    // The glTF nodes carry no names: each gets its mesh's name or its index path.
    const char* pistons[] = {"/ROOT/node_1/node_1_11/Piston_123-844_0_Parts_1",
                             "/ROOT/node_1/node_1_12/Piston_123-844_0_Parts_1"};
    for (const char* path : pistons) {
        const int piston = scene.findNode(path);
        ASSERT_GE(piston, 0) << path;
        EXPECT_TRUE(scene.nodes[size_t(piston)].generatedName);
        EXPECT_EQ(scene.nodes[size_t(piston)].meshes.size(), 2u);
    }
    EXPECT_GE(scene.findNode("/ROOT/node_1/rod_123-699_0_Parts_1#2"), 0);
    EXPECT_EQ(scene.findNodesByName("Spring_Link__0_Parts_1").size(), 20u);
    EXPECT_GT(scene.instancedTriangleCount(), 70000u);
}

TEST(RealScenes, EngineInMillimetresWhenTheUserSaysSo)
{
    const auto file = sceneFile("2CylinderEngine.glb");
    SKIP_UNLESS_PRESENT(file);
    ImportOptions options;
    options.metresPerUnit = 0.001;
    const ImportedScene metres = importScene(file);
    const ImportedScene millimetres = importScene(file, options);
    const int piston = metres.findNode("/ROOT/node_1/node_1_11/Piston_123-844_0_Parts_1");
    ASSERT_GE(piston, 0);
    EXPECT_TRUE((millimetres.worldTransform(piston).block<3, 1>(0, 3) * 1000.0)
                    .isApprox(metres.worldTransform(piston).block<3, 1>(0, 3), 1e-9));
}

TEST(RealScenes, IfcBuildingImportsInMetresYUpWithNamedElements)
{
    const auto file = sceneFile("AC14-FZK-Haus.ifc");
    SKIP_UNLESS_PRESENT(file);
    const ImportedScene scene = importScene(file);
    EXPECT_EQ(scene.format, "IFC");
    EXPECT_GT(scene.nodes.size(), 100u);
    EXPECT_GT(scene.instancedTriangleCount(), 10000u);
    bool foundWall = false;
    for (const SceneNode& node : scene.nodes)
        foundWall = foundWall || node.name.rfind("IfcWallStandardCase_", 0) == 0;
    EXPECT_TRUE(foundWall);
    // A house is a few metres tall and ~10 m wide: +Y up and metres.
    Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9), high = -low;
    for (size_t n = 0; n < scene.nodes.size(); ++n) {
        const Mat4 world = scene.worldTransform(int(n));
        for (int m : scene.nodes[n].meshes) {
            const SceneMesh& mesh = scene.meshes[size_t(m)];
            for (size_t i = 0; i < mesh.positions.size(); i += 3) {
                const Eigen::Vector4d p(mesh.positions[i], mesh.positions[i + 1],
                                        mesh.positions[i + 2], 1);
                const Eigen::Vector3d w = (world * p).head<3>();
                low = low.cwiseMin(w);
                high = high.cwiseMax(w);
            }
        }
    }
    const Eigen::Vector3d size = high - low;
    EXPECT_GT(size.x(), 5.0);
    EXPECT_LT(size.x(), 100.0);
    EXPECT_GT(size.y(), 3.0);
    EXPECT_LT(size.y(), 20.0);
}

} // namespace
} // namespace chaintube::formats
