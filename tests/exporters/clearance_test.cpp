// Clearance analysis of projects and `chaintube check`.
#include "cli_run.h"
#include "export_test_support.h"

#include <array>
#include <chaintube/export/clearance.h>
#include <chaintube/formats/collider_exemption.h>
#include <chaintube/formats/project.h>
#include <chaintube/formats/project_hoses.h>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sys/wait.h>

namespace chaintube::exporting::testing {
namespace {

/// An OBJ with three boxes: "near" 10 mm from the hose's surface, "touching" crossing the
/// hose, "far" 1 m away.
void writeBoxes(const fs::path& file)
{
    std::ofstream out(file);
    int base = 1;
    auto box = [&](const char* name, Vec3 lo, Vec3 hi) {
        out << "o " << name << "\n";
        for (int i = 0; i < 8; ++i)
            out << "v " << ((i & 1) ? hi.x() : lo.x()) << " " << ((i & 2) ? hi.y() : lo.y()) << " "
                << ((i & 4) ? hi.z() : lo.z()) << "\n";
        const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                 {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (const auto& f : faces)
            out << "f " << base + f[0] << " " << base + f[1] << " " << base + f[2] << " "
                << base + f[3] << "\n";
        base += 8;
    };
    box("near", {0.4, 0.02, -0.1}, {0.6, 0.2, 0.1});        // axis 20 mm below: surface 10 mm
    box("touching", {0.85, -0.005, -0.1}, {0.9, 0.2, 0.1}); // crosses the axis
    box("far", {0.4, 1.0, -0.1}, {0.6, 1.2, 0.1});
}

/// A project with one scene (the boxes) and one straight 20 mm hose from (0,0,0) to (1,0,0).
fs::path writeProject(const fs::path& folder, bool attachToNear = false)
{
    writeBoxes(folder / "boxes.obj");
    formats::Project project =
        formats::loadProject(fs::path(CHAINTUBE_SAMPLES_DIR) / "single-hose.ctproj");
    formats::SceneReference scene;
    scene.id = "boxes";
    scene.path = "boxes.obj";
    project.scenes = {scene};
    project.hoses.resize(1);
    formats::HoseDefinition& hose = project.hoses[0];
    hose.id = "probe";
    hose.route = {{0, 0, 0}, {1, 0, 0}};
    hose.length = 1.0; // the sample's hose is 0.6 m long: this one is as long as its route
    hose.outerDiameter = 0.02;
    hose.segmentCount = 20;
    hose.attachments.clear();
    if (attachToNear) {
        const formats::ImportedScene imported = formats::importScene(folder / "boxes.obj", {});
        const std::vector<int> nodes = imported.findNodesByName("near");
        if (nodes.empty()) throw std::runtime_error("no node named near");
        formats::HoseAttachment a;
        a.scene = "boxes";
        a.node = imported.nodes[static_cast<size_t>(nodes.front())].path;
        a.offset = imported.worldFrame(nodes.front()).inverse();
        a.firstPoint = a.lastPoint = 10;
        hose.attachments = {a};
    }
    const fs::path file = folder / "probe.ctproj";
    formats::saveProject(project, file);
    return file;
}

TEST(Clearance, GeneratedSceneListsEachObjectCloserThanTheThreshold)
{
    TemporaryFolder folder;
    const fs::path project = writeProject(folder.path());
    ClearanceOptions options;
    options.threshold = 0.015;
    const std::vector<ClearanceFinding> found = checkProjectClearance(project, {}, options);
    ASSERT_EQ(found.size(), 2u);
    // Closest first: the box crossing the hose (inside by the full radius), then "near".
    EXPECT_NE(found[0].objectPath.find("touching"), std::string::npos) << found[0].objectPath;
    EXPECT_NEAR(found[0].distance, -0.01, 1e-9);
    EXPECT_TRUE(found[0].axisPoint == 17 || found[0].axisPoint == 18);
    EXPECT_NE(found[1].objectPath.find("near"), std::string::npos) << found[1].objectPath;
    EXPECT_EQ(found[1].hoseId, "probe");
    EXPECT_EQ(found[1].sceneId, "boxes");
    EXPECT_NEAR(found[1].distance, 0.01, 1e-6); // float vertices
    EXPECT_NEAR(found[1].onObject.y(), 0.02, 1e-6);
    EXPECT_NEAR(found[1].onHose.y(), 0.01, 1e-6);
    EXPECT_GE(found[1].onObject.x(), 0.4 - 1e-6);
    EXPECT_LE(found[1].onObject.x(), 0.6 + 1e-6);
    EXPECT_GE(found[1].axisPoint, 8);
    EXPECT_LE(found[1].axisPoint, 12);
    // Below the near box's clearance only the crossing box remains.
    options.threshold = 0.005;
    EXPECT_EQ(checkProjectClearance(project, {}, options).size(), 1u);
}

// A gravity hose is checked as it hangs (the shape the editor shows and the export writes),
// not along its route: rig-options' valve tail hangs towards the floor plate. Before, the check
// measured the route.
TEST(Clearance, GravityHosesAreCheckedAsTheyHang)
{
    const fs::path file = testDataDir() / "rig-options.ctproj";
    const formats::Project project = loadWithRoots(file);
    const formats::ImportedScenes scenes = formats::importProjectScenes(project, file, roots());
    const std::vector<Hose> route = formats::buildHoses(project, scenes);
    std::vector<Hose> hanging = route;
    int gravityHoses = 0;
    for (size_t h = 0; h < hanging.size(); ++h)
        gravityHoses +=
            formats::settleUnderGravity(hanging[h], project.hoses[h], project, scenes) > 0;
    ASSERT_GE(gravityHoses, 1);
    ClearanceOptions options;
    options.threshold = 1.0; // everything within a metre: the distances themselves are compared
    const std::vector<SceneObject> objects = sceneObjects(project, scenes);
    const std::vector<ClearanceFinding> expected =
        clearanceViolations(project, hanging, objects, options);
    const std::vector<ClearanceFinding> alongRoute =
        clearanceViolations(project, route, objects, options);
    const std::vector<ClearanceFinding> checked = checkProjectClearance(file, roots(), options);
    ASSERT_EQ(checked.size(), expected.size());
    double largestChange = 0.0;
    for (size_t f = 0; f < checked.size(); ++f) {
        EXPECT_EQ(checked[f].hoseId, expected[f].hoseId) << f;
        EXPECT_EQ(checked[f].objectPath, expected[f].objectPath) << f;
        EXPECT_NEAR(checked[f].distance, expected[f].distance, 1e-12) << f;
        for (const ClearanceFinding& r : alongRoute)
            if (r.hoseId == checked[f].hoseId && r.objectPath == checked[f].objectPath)
                largestChange = std::max(largestChange, std::abs(r.distance - checked[f].distance));
    }
    // Otherwise the comparison above could not tell the route from the hanging shape.
    EXPECT_GT(largestChange, 1e-3)
        << "the hanging tail is farther from or nearer to some object than its route";
}

TEST(Clearance, AttachedNodesAreSkippedUnlessAsked)
{
    TemporaryFolder folder;
    const fs::path project = writeProject(folder.path(), true);
    ClearanceOptions options;
    options.threshold = 0.015;
    const std::vector<ClearanceFinding> skipped = checkProjectClearance(project, {}, options);
    ASSERT_EQ(skipped.size(), 1u);
    EXPECT_NE(skipped[0].objectPath.find("touching"), std::string::npos);
    options.includeAttachedNodes = true;
    EXPECT_EQ(checkProjectClearance(project, {}, options).size(), 2u);
}

TEST(Clearance, AncestorsOfAnAttachedNodeAreSkippedButItsSiblingsAndChildrenAreNot)
{
    // Four objects crossing the hose, named like a scene graph; the hose is attached to
    // "/rig/valve/inlet". Its ancestors "/rig/valve" (the part the fitting belongs to) and
    // "/rig" are skipped with it; the sibling "/rig/valve/outlet", the child
    // "/rig/valve/inlet/seal" and "/rig/valveX" (a name prefix, not an ancestor) are reported.
    formats::Project project =
        formats::loadProject(fs::path(CHAINTUBE_SAMPLES_DIR) / "single-hose.ctproj");
    project.hoses.resize(1);
    formats::HoseAttachment attachment;
    attachment.scene = "rig";
    attachment.node = "/rig/valve/inlet";
    project.hoses[0].attachments = {attachment};
    project.hoses[0].id = "probe";
    HoseSpec spec;
    spec.segmentCount = 20;
    const std::vector<Hose> hoses{Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, spec)};
    std::vector<SceneObject> objects;
    const char* paths[] = {"/rig",
                           "/rig/valve",
                           "/rig/valve/inlet",
                           "/rig/valve/outlet",
                           "/rig/valve/inlet/seal",
                           "/rig/valveX"};
    for (int o = 0; o < 6; ++o) {
        const double x = 0.1 + 0.15 * o;
        const std::vector<Vec3> corners{
            {x, -0.1, -0.1}, {x, 0.1, -0.1}, {x, 0.1, 0.1}, {x, -0.1, 0.1}};
        objects.push_back(
            {"rig", o, paths[o], MeshCollider::fromArrays(corners, {0, 1, 2, 0, 2, 3})});
    }
    ClearanceOptions options;
    options.threshold = 0.005;
    std::vector<ClearanceFinding> found = clearanceViolations(project, hoses, objects, options);
    std::set<std::string> reported;
    for (const ClearanceFinding& f : found)
        reported.insert(f.objectPath);
    EXPECT_EQ(reported,
              (std::set<std::string>{"/rig/valve/outlet", "/rig/valve/inlet/seal", "/rig/valveX"}));
    // The same node in another scene is not the attached one.
    for (SceneObject& object : objects)
        object.sceneId = "other";
    EXPECT_EQ(clearanceViolations(project, hoses, objects, options).size(), 6u);
    for (SceneObject& object : objects)
        object.sceneId = "rig";
    options.includeAttachedNodes = true;
    EXPECT_EQ(clearanceViolations(project, hoses, objects, options).size(), 6u);
}

TEST(ColliderExemption, TheAttachmentNodeAndItsAncestorsAreExemptNotItsSiblingsChildrenOrNamesakes)
{
    // 0 root ─ 1 valve ─ 2 inlet ─ 4 seal;  0 ─ 3 floor;  5 a second root
    const std::vector<int> parents{-1, 0, 1, 0, 2, -1};
    const auto parentOf = [&](int n) { return parents[static_cast<size_t>(n)]; };
    EXPECT_TRUE(formats::attachmentExempts(2, 2, parentOf));
    EXPECT_TRUE(formats::attachmentExempts(2, 1, parentOf));
    EXPECT_TRUE(formats::attachmentExempts(2, 0, parentOf));
    EXPECT_FALSE(formats::attachmentExempts(2, 3, parentOf));  // sibling of the valve
    EXPECT_FALSE(formats::attachmentExempts(2, 4, parentOf));  // child of the attachment node
    EXPECT_FALSE(formats::attachmentExempts(2, 5, parentOf));  // another tree
    EXPECT_FALSE(formats::attachmentExempts(-1, 0, parentOf)); // fixed to the world
    EXPECT_FALSE(formats::attachmentExempts(2, -1, parentOf));

    EXPECT_TRUE(formats::attachmentExemptsPath("/rig/valve/inlet", "/rig/valve/inlet"));
    EXPECT_TRUE(formats::attachmentExemptsPath("/rig/valve/inlet", "/rig/valve"));
    EXPECT_TRUE(formats::attachmentExemptsPath("/rig/valve/inlet", "/rig"));
    EXPECT_FALSE(formats::attachmentExemptsPath("/rig/valve/inlet", "/rig/val"));
    EXPECT_FALSE(formats::attachmentExemptsPath("/rig/valveX/inlet", "/rig/valve"));
    EXPECT_FALSE(formats::attachmentExemptsPath("/rig/valve", "/rig/valve/inlet"));
    EXPECT_FALSE(formats::attachmentExemptsPath("/rig/valve", "/rig/floor"));
    EXPECT_FALSE(formats::attachmentExemptsPath("", "/rig"));
    EXPECT_FALSE(formats::attachmentExemptsPath("/rig", ""));
}

TEST(Clearance, BadThresholdIsRefusedNamingIt)
{
    TemporaryFolder folder;
    const fs::path project = writeProject(folder.path());
    ClearanceOptions options;
    options.threshold = -0.001;
    try {
        checkProjectClearance(project, {}, options);
        FAIL() << "no error";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("clearance threshold"), std::string::npos) << e.what();
    }
}

TEST(ClearanceCli, ListsEveryViolationAndExitsThree)
{
    TemporaryFolder folder;
    const fs::path project = writeProject(folder.path());
    const CliRun run = runCli("check \"" + project.string() + "\" --clearance 0.015");
    EXPECT_EQ(run.exitCode, 3) << run.output;
    EXPECT_NE(run.output.find("violation: hose probe, object boxes:"), std::string::npos)
        << run.output;
    EXPECT_NE(run.output.find("near, distance 0.01"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("axis point"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("2 clearance violation(s) below 0.015 m"), std::string::npos)
        << run.output;
}

TEST(ClearanceCli, SampleTestRigSkipsThePartsTheHosesAreFittedToAndListsTheRest)
{
    // left-feed is attached to /test-rig/valve/valve_inlet: its end sits in the valve body,
    // the inlet's parent, by design. That used to be reported (the ancestor was not skipped);
    // at 5 mm nothing else is close, at 50 mm the floor plate under the hose is.
    const fs::path sample = fs::path(CHAINTUBE_SAMPLES_DIR) / "test-rig.ctproj";
    const CliRun run = runCli("check \"" + sample.string() + "\" --clearance 0.005");
    EXPECT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(run.output.find("/test-rig/valve"), std::string::npos) << run.output;
    const CliRun wide = runCli("check \"" + sample.string() + "\" --clearance 0.05");
    EXPECT_EQ(wide.exitCode, 3) << wide.output;
    EXPECT_NE(wide.output.find("violation: hose left-feed, object rig:/test-rig/floor_plate"),
              std::string::npos)
        << wide.output;
    EXPECT_EQ(wide.output.find("/test-rig/valve"), std::string::npos) << wide.output;
    const CliRun single =
        runCli("check \"" + (fs::path(CHAINTUBE_SAMPLES_DIR) / "single-hose.ctproj").string() +
               "\" --clearance 0.005");
    EXPECT_EQ(single.exitCode, 0) << single.output;
    EXPECT_NE(single.output.find("0 clearance violation(s)"), std::string::npos) << single.output;
}

// Without --clearance, check uses the project's own threshold ("checks"/"clearance"), and the
// default 5 mm when the project sets none; --clearance still overrides it.
TEST(ClearanceCli, WithoutOptionsTheProjectsOwnThresholdIsUsed)
{
    TemporaryFolder folder;
    fs::create_directories(folder / "scenes");
    fs::copy_file(fs::path(CHAINTUBE_SAMPLES_DIR) / "scenes/test-rig.gltf",
                  folder / "scenes/test-rig.gltf");
    formats::Project rig =
        formats::loadProject(fs::path(CHAINTUBE_SAMPLES_DIR) / "test-rig.ctproj");
    ASSERT_FALSE(rig.checks.clearance) << "the sample sets none";
    rig.checks.clearance = 0.05;
    const fs::path wide = folder / "wide.ctproj";
    formats::saveProject(rig, wide);
    const CliRun own = runCli("check \"" + wide.string() + "\"");
    EXPECT_EQ(own.exitCode, 3) << own.output;
    EXPECT_NE(own.output.find("violation: hose left-feed, object rig:/test-rig/floor_plate"),
              std::string::npos)
        << own.output;
    EXPECT_NE(own.output.find("below 0.05 m (the project's threshold)"), std::string::npos)
        << own.output;
    const CliRun overridden = runCli("check \"" + wide.string() + "\" --clearance 0.0001");
    EXPECT_EQ(overridden.exitCode, 0) << overridden.output;

    const CliRun fallback = runCli(
        "check \"" + (fs::path(CHAINTUBE_SAMPLES_DIR) / "single-hose.ctproj").string() + "\"");
    EXPECT_EQ(fallback.exitCode, 0) << fallback.output;
    EXPECT_NE(fallback.output.find("0 clearance violation(s) below 0.005 m (the default "
                                   "threshold: the project sets none)"),
              std::string::npos)
        << fallback.output;
}

TEST(ClearanceCli, BadInputIsNamedWithItsExitCode)
{
    EXPECT_EQ(runCli("check --help").exitCode, 0);
    const CliRun missing = runCli("check /nonexistent/x.ctproj");
    EXPECT_EQ(missing.exitCode, 1) << "no option: the project's threshold, read from the file";
    EXPECT_NE(missing.output.find("/nonexistent/x.ctproj"), std::string::npos) << missing.output;
    const CliRun negative = runCli("check x.ctproj --clearance -0.1");
    EXPECT_EQ(negative.exitCode, 2);
    EXPECT_NE(negative.output.find("expected a distance >= 0 in metres"), std::string::npos)
        << negative.output;
    const CliRun absent = runCli("check /nonexistent/absent.ctproj --clearance 0.005");
    EXPECT_EQ(absent.exitCode, 1);
    EXPECT_NE(absent.output.find("/nonexistent/absent.ctproj"), std::string::npos) << absent.output;
    const CliRun badRoot = runCli("check x.ctproj --clearance 0.005 --root nonsense");
    EXPECT_EQ(badRoot.exitCode, 2);
    EXPECT_NE(badRoot.output.find("--root 'nonsense': expected NAME=DIR"), std::string::npos)
        << badRoot.output;
}

} // namespace
} // namespace chaintube::exporting::testing
