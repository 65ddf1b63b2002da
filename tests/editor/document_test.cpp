// Document and undo commands: every command's undo restores the document exactly (compared
// through serialiseProject plus the pose overrides), redo gives the edited state exactly, and
// slider-like edits merge into one undo step. Runs under QT_QPA_PLATFORM=offscreen.
#include "chaintube/editor/commands.h"
#include "chaintube/editor/document.h"
#include "test_support.h"

#include <Eigen/Geometry>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>

namespace chaintube::editor {
namespace {

using test::roots;
using test::samplesDir;

std::string readFile(const std::filesystem::path& file)
{
    std::ifstream stream(file, std::ios::binary);
    std::ostringstream text;
    text << stream.rdbuf();
    return text.str();
}

std::unique_ptr<Document> openTestRig()
{
    auto document = std::make_unique<Document>(roots());
    document->adopt(readProject(samplesDir() / "test-rig.ctproj", roots()));
    return document;
}

/// Pushes the command and checks: the state changed, undo restores it byte for byte, redo
/// gives the edited state byte for byte, and the live hoses follow.
void expectExactUndo(Document& document, QUndoCommand* command)
{
    document.closeMerge(); // each call is a separate edit
    const std::string before = document.stateFingerprint();
    std::vector<std::vector<Vec3>> pointsBefore;
    for (const auto& hose : document.project().hoses)
        pointsBefore.push_back(document.hose(hose.id) ? document.hose(hose.id)->points()
                                                      : std::vector<Vec3>{});
    document.undoStack()->push(command);
    const std::string after = document.stateFingerprint();
    ASSERT_NE(before, after) << "the command changed nothing";
    document.undoStack()->undo();
    EXPECT_EQ(before, document.stateFingerprint());
    ASSERT_EQ(pointsBefore.size(), document.project().hoses.size());
    for (size_t i = 0; i < pointsBefore.size(); ++i) {
        const Hose* hose = document.hose(document.project().hoses[i].id);
        ASSERT_TRUE(hose);
        EXPECT_EQ(pointsBefore[i], hose->points()) << "hose " << i << " not restored";
    }
    document.undoStack()->redo();
    EXPECT_EQ(after, document.stateFingerprint());
}

TEST(Document, OpensTheTestRigWithItsSceneAndHoses)
{
    auto document = openTestRig();
    ASSERT_EQ(document->hoseCount(), 2);
    ASSERT_TRUE(document->scene("rig"));
    EXPECT_GE(document->scene("rig")->findNode("/test-rig/valve"), 0);
    for (const auto& hose : document->project().hoses)
        EXPECT_TRUE(document->hose(hose.id)) << document->hoseBuildError(hose.id);
    EXPECT_FALSE(document->isModified());
}

TEST(DocumentUndo, EveryHoseFieldChangeUndoesExactly)
{
    auto document = openTestRig();
    const std::string id = document->project().hoses[0].id;
    using formats::HoseDefinition;
    expectExactUndo(*document, makeChangeHoseField(*document, id, &HoseDefinition::outerDiameter,
                                                   0.031, MergeId::HoseDiameter, "diameter"));
    expectExactUndo(*document, makeChangeHoseField(*document, id, &HoseDefinition::segmentCount, 24,
                                                   MergeId::HoseSegments, "segments"));
    expectExactUndo(*document,
                    makeChangeHoseField(*document, id, &HoseDefinition::name,
                                        std::string("renamed"), MergeId::HoseName, "name"));
    formats::Rgba colour{0.9, 0.1, 0.2, 1.0};
    expectExactUndo(*document, makeChangeHoseField(*document, id, &HoseDefinition::colour, colour,
                                                   MergeId::HoseColour, "colour"));
    Material material;
    material.expansionCoefficient = 0.2;
    material.bendLimit = BendLimit::deflectionAngle(0.5);
    expectExactUndo(*document, makeChangeHoseField(*document, id, &HoseDefinition::material,
                                                   formats::MaterialChoice(material),
                                                   MergeId::HoseMaterial, "material"));
    formats::ProfileSpec profile;
    profile.shape = Profile::Shape::Rectangle;
    profile.width = 0.03;
    profile.height = 0.012;
    expectExactUndo(*document, makeChangeHoseField(*document, id, &HoseDefinition::profile, profile,
                                                   MergeId::HoseProfile, "profile"));
}

TEST(DocumentUndo, RouteEditsUndoExactly)
{
    auto document = openTestRig();
    const auto& hose = document->project().hoses[0];
    std::vector<Vec3> inserted = hose.route;
    inserted.insert(inserted.begin() + 2, 0.5 * (inserted[1] + inserted[2]) + Vec3(0, 0.05, 0));
    expectExactUndo(*document, makeSetRoute(*document, hose.id, inserted, "insert"));
    std::vector<Vec3> deleted = document->project().hoses[0].route;
    deleted.erase(deleted.begin() + 1);
    expectExactUndo(*document, makeSetRoute(*document, hose.id, deleted, "delete"));
    std::vector<Vec3> moved = document->project().hoses[0].route;
    moved[1] += Vec3(0.02, 0.03, -0.01);
    expectExactUndo(*document, makeSetRoute(*document, hose.id, moved, "move"));
}

TEST(DocumentUndo, AddAndRemoveHoseUndoExactly)
{
    auto document = openTestRig();
    formats::HoseDefinition definition;
    definition.id = document->unusedHoseId();
    definition.name = "new";
    definition.route = {Vec3(0, 0.3, 0), Vec3(0.2, 0.35, 0.1), Vec3(0.3, 0.3, 0.3)};
    expectExactUndo(*document, new AddHoseCommand(*document, definition));
    EXPECT_TRUE(document->hose(definition.id));
    expectExactUndo(*document, new RemoveHoseCommand(*document, document->project().hoses[0].id));
    EXPECT_EQ(document->hoseCount(), 2);
}

TEST(DocumentUndo, AttachAndDetachUndoExactly)
{
    auto document = openTestRig();
    const auto& rig = *document->scene("rig");
    const int floor = rig.findNode("/test-rig/floor_plate");
    ASSERT_GE(floor, 0);
    const std::string id = document->project().hoses[0].id;
    expectExactUndo(*document, makeAttach(*document, id, 7, 8, "rig", floor));
    EXPECT_TRUE(document->hose(id)->isFixed(7));
    expectExactUndo(*document, makeDetach(*document, id, 0));
    EXPECT_THROW(makeAttach(*document, id, 7, 7, "rig", floor), InvalidArgument)
        << "overlapping range must be refused";
}

TEST(DocumentUndo, MovingAPartMovesTheFixedSegmentAndUndoesExactly)
{
    auto document = openTestRig();
    const auto& rig = *document->scene("rig");
    const int valve = rig.findNode("/test-rig/valve");
    const auto& right = document->project().hoses[1]; // last point fixed to the valve
    const int last = document->hose(right.id)->pointCount() - 1;
    const Vec3 before = document->hose(right.id)->point(last);
    formats::Mat4 moved = document->nodeLocalTransform("rig", valve);
    moved(0, 3) += 0.05;
    moved(2, 3) -= 0.03;
    expectExactUndo(*document, makeSetNodeTransform(*document, {"rig", valve}, moved));
    const Vec3 after = document->hose(right.id)->point(last);
    EXPECT_NEAR((after - before - Vec3(0.05, 0, -0.03)).norm(), 0.0, 1e-9);
    document->undoStack()->undo();
    EXPECT_NEAR((document->hose(right.id)->point(last) - before).norm(), 0.0, 0.0);
}

TEST(DocumentUndo, PresetsAndExportSettingsUndoExactly)
{
    auto document = openTestRig();
    auto presets = document->project().materialPresets;
    formats::MaterialPreset own;
    own.name = "my silicone hose";
    own.description = "soft";
    own.material.expansionCoefficient = 0.15;
    own.material.bendLimit = BendLimit::minBendRadius(0.04);
    presets.push_back(own);
    expectExactUndo(*document, makeSetPresets(*document, presets, "save preset"));
    formats::ExportSettings settings = document->project().exportSettings;
    settings.format = "gltf";
    settings.path = "out.gltf";
    expectExactUndo(*document, makeSetExportSettings(*document, settings));
}

TEST(DocumentUndo, ImportingASceneUndoesExactly)
{
    Document document(roots());
    formats::SceneReference reference;
    reference.id = "rig";
    reference.path = (samplesDir() / "scenes/test-rig.gltf").string();
    auto scene = formats::importScene(samplesDir() / "scenes/test-rig.gltf");
    expectExactUndo(document, new AddSceneCommand(document, reference, scene));
    EXPECT_TRUE(document.scene("rig"));
    document.undoStack()->undo();
    EXPECT_FALSE(document.scene("rig"));
}

TEST(DocumentUndo, CommittedDragUndoesExactly)
{
    auto document = openTestRig();
    const std::string id = document->project().hoses[0].id;
    const std::string before = document->stateFingerprint();
    const std::vector<Vec3> pointsBefore = document->hose(id)->points();
    const Vec3 start = document->hose(id)->point(8);
    for (int step = 1; step <= 10; ++step)
        ASSERT_NE(
            document->dragHosePoint(id, 8, start + Vec3(0, 0.006 * step, 0.004 * step)).status,
            Status::InvalidInput);
    EXPECT_NE(pointsBefore, document->hose(id)->points());
    EXPECT_EQ(before, document->stateFingerprint()) << "a drag is not an edit until committed";
    // The release converges fully (commitHoseDrag does it too; nothing is left for it here).
    static_cast<void>(document->finishHoseDrag(id));
    EXPECT_FALSE(document->hose(id)->pending());
    EXPECT_EQ(before, document->stateFingerprint()) << "finishing a drag is not an edit either";
    // (The hose may be taut before the target: compare with where the drag left it.)
    const Vec3 dragged = document->hose(id)->point(8);
    EXPECT_GT((dragged - start).norm(), 0.02);
    ASSERT_TRUE(document->commitHoseDrag(id));
    EXPECT_EQ(document->undoStack()->count(), 1);
    EXPECT_NEAR((document->hose(id)->point(8) - dragged).norm(), 0.0, 0.01)
        << "the rebuilt hose keeps the dragged shape";
    document->undoStack()->undo();
    EXPECT_EQ(before, document->stateFingerprint());
    EXPECT_EQ(pointsBefore, document->hose(id)->points());
}

TEST(DocumentLength, TwentyCommittedDragsWithinTheBandKeepTheRestLengthAndTheShape)
{
    auto document = openTestRig();
    const std::string id = "left-feed";
    const double length = *document->hoseDefinition(id)->length;
    ASSERT_NEAR(document->hose(id)->restLengthTotal(), length, 1e-12);
    for (int drag = 0; drag < 20; ++drag) {
        const int point = 4 + drag % 9;
        const Vec3 start = document->hose(id)->point(point);
        // Up and out by a centimetre, then a little more: the hose stretches within its band.
        const Vec3 offset = Vec3(0.0, 0.004 + 0.0005 * drag, drag % 2 ? 0.006 : -0.006);
        for (int step = 1; step <= 5; ++step)
            static_cast<void>(document->dragHosePoint(id, point, start + offset * step / 5.0));
        // The release's convergence (commitHoseDrag does it too; nothing is left for it here).
        static_cast<void>(document->finishHoseDrag(id));
        EXPECT_FALSE(document->hose(id)->pending()) << drag;
        const std::vector<Vec3> dragged = document->hose(id)->points();
        ASSERT_TRUE(document->commitHoseDrag(id, point)) << drag;
        const Hose& hose = *document->hose(id);
        EXPECT_NEAR(hose.restLengthTotal(), length, 1e-9) << drag;
        EXPECT_EQ(*document->hoseDefinition(id)->length, length) << drag;
        for (int i = 0; i < hose.pointCount(); ++i)
            ASSERT_NEAR((hose.point(i) - dragged[size_t(i)]).norm(), 0.0, 1e-9)
                << "drag " << drag << ": the committed hose is the dragged one, point " << i;
        for (int s = 0; s < hose.segmentCount(); ++s) {
            const double segment = (hose.point(s + 1) - hose.point(s)).norm();
            EXPECT_LE(segment, hose.maxLength(s) * (1 + 1e-9)) << drag << ' ' << s;
            EXPECT_GE(segment, hose.minLength(s) * (1 - 1e-9)) << drag << ' ' << s;
        }
    }
    EXPECT_EQ(document->undoStack()->count(), 20);
    // Save and reopen: the same shape and the same length.
    const std::filesystem::path folder = test::outputDir() / "twenty-drags";
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf");
    const std::vector<Vec3> shape = document->hose(id)->points();
    document->save(folder / "test-rig.ctproj");
    Document reopened(roots());
    reopened.adopt(readProject(folder / "test-rig.ctproj", roots()));
    EXPECT_EQ(*reopened.hoseDefinition(id)->length, length);
    EXPECT_NEAR(reopened.hose(id)->restLengthTotal(), length, 1e-9);
    for (int i = 0; i < reopened.hose(id)->pointCount(); ++i)
        EXPECT_NEAR((reopened.hose(id)->point(i) - shape[size_t(i)]).norm(), 0.0, 1e-12) << i;
}

TEST(DocumentLength, AHoseWithoutALengthKeepsTheOneItHadWhenADragIsCommitted)
{
    auto document = openTestRig();
    const std::string id = test::addCantilever(*document); // made in code: no length of its own
    ASSERT_FALSE(document->hoseDefinition(id)->length);
    const double length = document->hose(id)->restLengthTotal();
    const Vec3 end = document->hose(id)->point(16);
    static_cast<void>(document->dragHosePoint(id, 16, end + Vec3(-0.05, 0.0, 0.0)));
    static_cast<void>(document->finishHoseDrag(id));
    ASSERT_GT(document->hose(id)->currentLength(), length * 1.01) << "pulled within its band";
    ASSERT_TRUE(document->commitHoseDrag(id, 16));
    ASSERT_TRUE(document->hoseDefinition(id)->length);
    EXPECT_NEAR(*document->hoseDefinition(id)->length, length, 1e-12);
    EXPECT_NEAR(document->hose(id)->restLengthTotal(), length, 1e-12);
}

TEST(DocumentLength, ChangingTheLengthIsOneUndoStepNamedAfterTheHose)
{
    auto document = openTestRig();
    const std::string id = "right-return";
    const double length = *document->hoseDefinition(id)->length;
    expectExactUndo(*document, makeSetHoseLength(*document, id, 1.1 * length));
    document->undoStack()->push(makeSetHoseLength(*document, id, 1.1 * length));
    EXPECT_EQ(document->undoStack()->text(document->undoStack()->count() - 1).toStdString(),
              "Change length of right bracket to valve");
    EXPECT_NEAR(document->hose(id)->restLengthTotal(), 1.1 * length, 1e-12);
    EXPECT_THROW(makeSetHoseLength(*document, id, -1.0), InvalidArgument);
}

TEST(DocumentPose, MovingAPartResolvesOnlyTheHosesItCarries)
{
    auto document = openTestRig();
    const formats::ImportedScene& rig = *document->scene("rig");
    std::map<std::string, int> shapeEvents;
    QObject::connect(document.get(), &Document::changed, [&](const ChangeEvent& event) {
        if (event.kind == ChangeEvent::Kind::HoseShapeChanged) ++shapeEvents[event.hoseId];
    });
    const auto revisions = [&] {
        std::map<std::string, std::uint64_t> r;
        for (const auto& hose : document->project().hoses)
            r[hose.id] = document->hose(hose.id)->revision();
        return r;
    };
    // The left bracket carries only left-feed's first segment: right-return, fixed to the
    // same scene (the right bracket and the valve), is not touched.
    const int bracket = rig.findNode("/test-rig/bracket_left");
    const auto before = revisions();
    formats::Mat4 moved = document->nodeLocalTransform("rig", bracket);
    moved(1, 3) += 0.01;
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", bracket}, moved));
    EXPECT_NE(revisions()["left-feed"], before.at("left-feed"));
    EXPECT_EQ(revisions()["right-return"], before.at("right-return"));
    EXPECT_EQ(shapeEvents["left-feed"], 1);
    EXPECT_EQ(shapeEvents["right-return"], 0);
    EXPECT_EQ(document->undoStack()->undoText(), "Move bracket_left");
    // The valve carries right-return's end and, through its child valve_inlet, left-feed's.
    shapeEvents.clear();
    const int valve = rig.findNode("/test-rig/valve");
    formats::Mat4 valveMoved = document->nodeLocalTransform("rig", valve);
    valveMoved(0, 3) += 0.01;
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", valve}, valveMoved));
    EXPECT_EQ(shapeEvents["left-feed"], 1);
    EXPECT_EQ(shapeEvents["right-return"], 1);
    // The floor plate carries no hose: nothing is re-solved.
    shapeEvents.clear();
    const auto still = revisions();
    const int floor = rig.findNode("/test-rig/floor_plate");
    formats::Mat4 floorMoved = document->nodeLocalTransform("rig", floor);
    floorMoved(1, 3) -= 0.01;
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", floor}, floorMoved));
    EXPECT_TRUE(shapeEvents.empty());
    EXPECT_EQ(revisions(), still);
}

TEST(DocumentPose, ThePartCentreIsTheMiddleOfItsBoundingBoxAndFollowsThePose)
{
    auto document = openTestRig();
    const formats::ImportedScene& rig = *document->scene("rig");
    const int valve = rig.findNode("/test-rig/valve");
    // Independently: every vertex of the valve and its children at their world transforms.
    Vec3 low = Vec3::Constant(1e300), high = Vec3::Constant(-1e300);
    for (size_t n = 0; n < rig.nodes.size(); ++n) {
        bool under = false;
        for (int m = int(n); m >= 0; m = rig.nodes[size_t(m)].parent)
            under = under || m == valve;
        if (!under) continue;
        for (int mesh : rig.nodes[n].meshes)
            for (size_t v = 0; v < rig.meshes[size_t(mesh)].vertexCount(); ++v) {
                const float* p = &rig.meshes[size_t(mesh)].positions[3 * v];
                const Vec3 world =
                    (rig.worldTransform(int(n)) * Vec3(p[0], p[1], p[2]).homogeneous()).head<3>();
                low = low.cwiseMin(world);
                high = high.cwiseMax(world);
            }
    }
    EXPECT_NEAR((document->partCentre("rig", valve) - 0.5 * (low + high)).norm(), 0.0, 1e-9);
    formats::Mat4 moved = document->nodeLocalTransform("rig", valve);
    moved.block<3, 1>(0, 3) += Vec3(0.1, 0.0, -0.05);
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", valve}, moved));
    EXPECT_NEAR(
        (document->partCentre("rig", valve) - 0.5 * (low + high) - Vec3(0.1, 0.0, -0.05)).norm(),
        0.0, 1e-9);
}

TEST(DocumentPose, TheRouteLineFollowsThePartsTheHoseIsFixedTo)
{
    auto document = openTestRig();
    const std::string id = "right-return";
    const std::vector<Vec3> route = document->hoseDefinition(id)->route;
    EXPECT_EQ(document->displayRoute(id), route) << "at the file pose: the route itself";
    const int valve = document->scene("rig")->findNode("/test-rig/valve");
    formats::Mat4 moved = document->nodeLocalTransform("rig", valve);
    const Vec3 shift(0.02, 0.03, 0.0);
    moved.block<3, 1>(0, 3) += shift;
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", valve}, moved));
    const std::vector<Vec3> shown = document->displayRoute(id);
    ASSERT_EQ(shown.size(), route.size());
    // The end fixed to the valve moves with it, the one on the (unmoved) bracket stays, and in
    // between the route point moves part of the way.
    EXPECT_NEAR((shown.back() - (route.back() + shift)).norm(), 0.0, 1e-9);
    EXPECT_NEAR((shown.front() - route.front()).norm(), 0.0, 1e-9);
    const Vec3 middle = shown[route.size() / 2] - route[route.size() / 2];
    EXPECT_GT(middle.norm(), 0.2 * shift.norm());
    EXPECT_LT(middle.norm(), 0.8 * shift.norm());
    EXPECT_EQ(document->hoseDefinition(id)->route, route) << "the route itself is unchanged";
}

TEST(DocumentColliders, FlaggingAPartAHoseRunsThroughPushesItOutOrKeepsItsLengthsAndSaysHowDeep)
{
    auto document = openTestRig();
    const formats::ImportedScene& rig = *document->scene("rig");
    // Move the right bracket onto left-feed's middle, then flag it. left-feed is not fixed to
    // that bracket: it is pushed out, as a collider moved onto it would push it, or, where its
    // length cannot go round the bracket, it keeps its shape with every segment in its band
    // and its result says how deep it runs in (the Problems panel lists that).
    const int bracket = rig.findNode("/test-rig/bracket_right");
    const Vec3 middle = document->hose("left-feed")->point(8);
    formats::Mat4 moved = document->nodeLocalTransform("rig", bracket);
    moved.block<3, 1>(0, 3) = Vec3(middle.x(), middle.y() - 0.09, middle.z()); // 1 cm into it
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", bracket}, moved));
    const std::vector<Vec3> through = document->hose("left-feed")->points();
    const std::shared_ptr<MeshCollider> box =
        formats::nodeCollider(rig, bracket, document->nodeWorldTransform("rig", bracket));
    ASSERT_LT(clearance(*document->hose("left-feed"), *box).distance, -0.005) << "runs through";
    document->undoStack()->push(makeSetCollider(*document, {"rig", bracket}, true));
    const Hose& hose = *document->hose("left-feed");
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const double segment = (hose.point(s + 1) - hose.point(s)).norm();
        EXPECT_LE(segment, hose.maxLength(s) * (1 + 1e-9)) << "segment " << s;
        EXPECT_GE(segment, hose.minLength(s) * (1 - 1e-9)) << "segment " << s;
    }
    const UpdateResult result = document->lastUpdate("left-feed");
    if (result.status == Status::Infeasible) {
        EXPECT_GT(result.penetration, 0.005) << "says how deep it runs in";
        EXPECT_EQ(hose.points(), through) << "keeps the shape it had";
    } else {
        EXPECT_GE(clearance(hose, *box).distance, -CollisionOptions{}.tolerance - 1e-9)
            << "pushed out";
    }
    std::cout << "[ colliders ] flagged onto left-feed: status " << int(result.status)
              << ", penetration " << result.penetration << " m" << std::endl;
    document->undoStack()->undo();
    EXPECT_EQ(document->hose("left-feed")->points(), through) << "undo: as before the flag";
}

TEST(DocumentUndo, DragOfAHoseFixedToAMovedPartIsRefusedWithAReason)
{
    auto document = openTestRig();
    const int valve = document->scene("rig")->findNode("/test-rig/valve");
    formats::Mat4 moved = document->nodeLocalTransform("rig", valve);
    moved(1, 3) += 0.02;
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", valve}, moved));
    const std::string id = document->project().hoses[1].id;
    ASSERT_NE(
        document->dragHosePoint(id, 5, document->hose(id)->point(5) + Vec3(0, 0.05, 0)).status,
        Status::InvalidInput);
    std::string why;
    EXPECT_FALSE(document->commitHoseDrag(id, 5, &why));
    EXPECT_NE(why.find("moved"), std::string::npos) << why;
    EXPECT_EQ(document->undoStack()->count(), 1);
}

TEST(DocumentUndo, ASliderDragIsOneUndoStepAndTwoDragsAreTwo)
{
    auto document = openTestRig();
    const std::string id = document->project().hoses[0].id;
    const double original = document->hoseDefinition(id)->outerDiameter;
    for (double d : {0.021, 0.022, 0.023, 0.024})
        document->undoStack()->push(makeChangeHoseField(*document, id,
                                                        &formats::HoseDefinition::outerDiameter, d,
                                                        MergeId::HoseDiameter, "diameter"));
    EXPECT_EQ(document->undoStack()->count(), 1);
    document->closeMerge(); // slider released
    for (double d : {0.025, 0.026})
        document->undoStack()->push(makeChangeHoseField(*document, id,
                                                        &formats::HoseDefinition::outerDiameter, d,
                                                        MergeId::HoseDiameter, "diameter"));
    EXPECT_EQ(document->undoStack()->count(), 2);
    document->undoStack()->undo();
    EXPECT_EQ(document->hoseDefinition(id)->outerDiameter, 0.024);
    document->undoStack()->undo();
    EXPECT_EQ(document->hoseDefinition(id)->outerDiameter, original);
}

TEST(DocumentUndo, DifferentHosesDoNotMerge)
{
    auto document = openTestRig();
    for (const auto& hose : std::vector<formats::HoseDefinition>(document->project().hoses))
        document->undoStack()->push(makeChangeHoseField(*document, hose.id,
                                                        &formats::HoseDefinition::outerDiameter,
                                                        0.03, MergeId::HoseDiameter, "diameter"));
    EXPECT_EQ(document->undoStack()->count(), 2);
}

TEST(Document, ValidationRefusesImpossibleValuesWithAReason)
{
    auto document = openTestRig();
    formats::HoseDefinition definition = document->project().hoses[0];
    definition.profile.shape = Profile::Shape::RoundedRectangle;
    definition.profile.width = 0.02;
    definition.profile.height = 0.01;
    definition.profile.cornerRadius = 0.02; // more than half the height
    EXPECT_FALSE(document->validateHoseDefinition(definition).empty());
    definition = document->project().hoses[0];
    definition.material = formats::PresetName{"no such preset"};
    EXPECT_FALSE(document->validateHoseDefinition(definition).empty());
    definition = document->project().hoses[0];
    definition.segmentCount = 4; // attachment at points 15–16 would be outside
    EXPECT_FALSE(document->validateHoseDefinition(definition).empty());
    EXPECT_TRUE(document->validateHoseDefinition(document->project().hoses[0]).empty());
}

TEST(Document, SaveThenOpenGivesTheSameProject)
{
    auto document = openTestRig();
    const std::string id = document->project().hoses[0].id;
    document->undoStack()->push(makeChangeHoseField(*document, id,
                                                    &formats::HoseDefinition::outerDiameter, 0.027,
                                                    MergeId::HoseDiameter, "diameter"));
    EXPECT_TRUE(document->isModified());
    // The relative scene path must stay valid: the scene is copied beside the saved file.
    const auto folder = test::outputDir() / "save-open";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    const auto file = folder / "saved.ctproj";
    document->save(file);
    EXPECT_FALSE(document->isModified());
    Document reopened(roots());
    reopened.adopt(readProject(file, roots()));
    EXPECT_EQ(formats::serialiseProject(document->project()),
              formats::serialiseProject(reopened.project()));
    EXPECT_EQ(document->hose(id)->points(), reopened.hose(id)->points());
}

TEST(Document, AMovedPartIsSavedAsAPoseAndRestoredOnOpen)
{
    auto document = openTestRig();
    const int valve = document->scene("rig")->findNode("/test-rig/valve");
    const auto& right = document->project().hoses[1]; // last point fixed to the valve
    formats::Mat4 moved = document->nodeLocalTransform("rig", valve);
    moved(0, 3) += 0.05;
    moved.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(0.5, Vec3::UnitY()).toRotationMatrix() * moved.topLeftCorner<3, 3>();
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", valve}, moved));
    ASSERT_EQ(document->project().poses.size(), 1u) << "the override is part of the project";
    EXPECT_EQ(document->project().poses[0].node, "/test-rig/valve");
    EXPECT_EQ(document->project().poses[0].localTransform, moved);

    const auto folder = test::outputDir() / "save-open-pose";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    const auto file = folder / "posed.ctproj";
    document->save(file);
    Document reopened(roots());
    reopened.adopt(readProject(file, roots()));
    EXPECT_EQ(reopened.nodeLocalTransform("rig", valve), moved) << "the pose is restored";
    EXPECT_EQ(formats::serialiseProject(reopened.project()),
              formats::serialiseProject(document->project()));
    // A fresh build at the saved pose: the fixed end sits on the moved valve (the live hose in
    // the first document got there by the same one-step move of its attachments).
    const Hose* hose = reopened.hose(right.id);
    ASSERT_TRUE(hose);
    EXPECT_LT((hose->point(hose->pointCount() - 1) -
               document->hose(right.id)->point(hose->pointCount() - 1))
                  .norm(),
              1e-12);
    // Saving again without an edit writes the same bytes.
    const auto again = folder / "posed-again.ctproj";
    reopened.save(again);
    EXPECT_EQ(readFile(again), readFile(file));

    // Undo back to the file pose: nothing to save any more.
    document->undoStack()->undo();
    EXPECT_TRUE(document->project().poses.empty());
}

TEST(Document, APoseOfANodeTheSceneNoLongerHasIsAClearError)
{
    formats::Project project = formats::loadProject(samplesDir() / "test-rig.ctproj");
    project.poses.push_back({"rig", "/test-rig/removed-part", formats::Mat4::Identity()});
    const auto folder = test::outputDir() / "stale-pose";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    formats::saveProject(project, folder / "stale.ctproj");
    try {
        readProject(folder / "stale.ctproj", roots());
        ADD_FAILURE() << "accepted";
    } catch (const formats::ProjectFormatError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("stale.ctproj"), std::string::npos) << message;
        EXPECT_NE(message.find("/poses/0/node"), std::string::npos) << message;
        EXPECT_NE(message.find("/test-rig/removed-part"), std::string::npos) << message;
    }
}

TEST(Document, ChangeEventsNameWhatChanged)
{
    auto document = openTestRig();
    std::vector<ChangeEvent> events;
    QObject::connect(document.get(), &Document::changed,
                     [&](const ChangeEvent& event) { events.push_back(event); });
    const std::string id = document->project().hoses[1].id;
    document->undoStack()->push(makeChangeHoseField(
        *document, id, &formats::HoseDefinition::segmentCount, 24, MergeId::HoseSegments, "s"));
    bool sawHoseChanged = false;
    for (const ChangeEvent& event : events)
        sawHoseChanged =
            sawHoseChanged || (event.kind == ChangeEvent::Kind::HoseChanged && event.hoseId == id);
    EXPECT_TRUE(sawHoseChanged);
    EXPECT_EQ(document->hose(id)->pointCount(), 25);
}

// --- live gravity and colliders
// ---------------------------------------------------------------------

/// Steps gravity as the editor's timer does until nothing moves; returns the steps that moved
/// something (bounded by the document's step budget).
int stepUntilSettled(Document& document)
{
    int moving = 0;
    while (document.gravityActive())
        moving += document.stepGravity() > 0 ? 1 : 0;
    return moving;
}

QUndoCommand* gravityOn(Document& document, const std::string& id)
{
    Gravity gravity = document.hoseDefinition(id)->gravity;
    gravity.enabled = true;
    return makeChangeHoseField(document, id, &formats::HoseDefinition::gravity, gravity,
                               MergeId::HoseDefinition, "Gravity on");
}

TEST(DocumentGravity, AHoseFixedAtOneEndSagsToTheLowestShapeItsConstraintsAllowThenStops)
{
    auto document = openTestRig();
    const std::string id = test::addCantilever(*document);
    const std::vector<Vec3> authored = document->hose(id)->points();
    EXPECT_EQ(document->stepGravity(), 0) << "gravity is off by default: nothing steps";
    EXPECT_FALSE(document->gravityActive());

    document->undoStack()->push(gravityOn(*document, id));
    const int steps = document->undoStack()->count();
    const std::string definitionState = document->stateFingerprint();
    EXPECT_TRUE(document->gravityActive()) << "turning gravity on starts the settling";
    const int moving = stepUntilSettled(*document);
    EXPECT_GT(moving, 0);
    ASSERT_EQ(document->gravityState(id), Document::GravityState::Settled)
        << "still moving after " << document->gravitySteps(id) << " steps";
    const Hose& hose = *document->hose(id);
    const double expected = test::lowestReachableY(hose);
    const double lowest = test::lowestY(hose.points());
    const double drop = authored[1].y() - expected;
    std::printf("cantilever: settled after %d steps; lowest point %.6f m, model equilibrium "
                "%.6f m (drop %.4f m, off by %.2f %% of it)\n",
                document->gravitySteps(id), lowest, expected, drop,
                100.0 * (lowest - expected) / drop);
    EXPECT_GT(drop, 0.1) << "the expected shape hangs well below the clamp";
    EXPECT_NEAR(lowest, expected, 0.02 * drop) << "sagged to the constrained equilibrium";
    EXPECT_EQ(hose.measureViolation().status, Status::Ok) << "constraints hold after settling";
    EXPECT_EQ(hose.point(0), authored[0]) << "fixed points stay";
    EXPECT_EQ(hose.point(1), authored[1]);

    // Settled: no further motion, no events, nothing on the undo stack, the route as authored.
    const std::vector<Vec3> settled = hose.points();
    int shapeEvents = 0;
    QObject::connect(document.get(), &Document::changed, [&](const ChangeEvent& e) {
        shapeEvents += e.kind == ChangeEvent::Kind::HoseShapeChanged ? 1 : 0;
    });
    for (int i = 0; i < 10; ++i)
        EXPECT_EQ(document->stepGravity(), 0);
    EXPECT_EQ(shapeEvents, 0);
    EXPECT_EQ(document->hose(id)->points(), settled);
    EXPECT_EQ(document->undoStack()->count(), steps) << "simulation steps are not edits";
    EXPECT_EQ(document->stateFingerprint(), definitionState) << "the route stays as authored";

    // Undo: gravity off, the authored shape exactly.
    document->undoStack()->undo();
    EXPECT_FALSE(document->hoseDefinition(id)->gravity.enabled);
    EXPECT_EQ(document->hose(id)->points(), authored);
    EXPECT_FALSE(document->gravityActive());
}

/// Mean height of a hose's axis points (world metres): lower when it sags between clamps,
/// where the lowest point is often a clamped end.
double meanY(const std::vector<Vec3>& points)
{
    double sum = 0.0;
    for (const Vec3& point : points)
        sum += point.y();
    return sum / double(points.size());
}

// A bend-limited hose between two clamps (the case that did not settle before lib commit
// c386f59). Only left-feed: right-return (fixed by single points, braided steel) "settles"
// Infeasible under gravity with the lib of c386f59 (107 % overstretch; reported to lib).
TEST(DocumentGravity, ABendLimitedHoseBetweenTwoClampsSagsAndSettles)
{
    auto document = openTestRig();
    const std::string id = "left-feed";
    const std::vector<Vec3> authored = document->hose(id)->points();
    document->undoStack()->push(gravityOn(*document, id));
    stepUntilSettled(*document);
    ASSERT_EQ(document->gravityState(id), Document::GravityState::Settled)
        << "still moving after " << document->gravitySteps(id) << " steps";
    const std::vector<Vec3> settled = document->hose(id)->points();
    std::printf("%s: settled after %d steps, mean height %.4f m -> %.4f m\n", id.c_str(),
                document->gravitySteps(id), meanY(authored), meanY(settled));
    EXPECT_LT(meanY(settled), meanY(authored) - 0.001) << "sagged";
    EXPECT_EQ(document->hose(id)->measureViolation().status, Status::Ok);
    EXPECT_EQ(document->stepGravity(), 0) << "settled: no jitter";
    EXPECT_EQ(document->hose(id)->points(), settled);
}

// Live gravity by the clock (the main window's timer, Document::advanceGravity): ticks of 1/45,
// 1/72, 1/90 or 1/120 s, or of random length, make one step of 1/90 s for every 1/90 s of time,
// so the hose falls at the same pace and by the same steps at any tick rate: after the same time
// the same shape as that many stepGravity() calls, bit for bit, and at rest the settled shape.
TEST(DocumentGravity, LiveGravityByTheClockFallsAtTheSamePaceAtAnyTickRate)
{
    const std::string id = "left-feed";
    const auto gravityDocument = [&] {
        auto document = openTestRig();
        document->undoStack()->push(gravityOn(*document, id));
        return document;
    };
    auto settled = gravityDocument();
    stepUntilSettled(*settled);
    ASSERT_EQ(settled->gravityState(id), Document::GravityState::Settled);
    const int settleSteps = settled->gravitySteps(id);
    ASSERT_GT(settleSteps, 10);

    std::mt19937 random(52);
    std::uniform_real_distribution<double> jitter(0.002, 0.05);
    for (double rate : {45.0, 72.0, 90.0, 120.0, 0.0}) { // 0: random ticks of 2 to 50 ms
        auto ticked = gravityDocument();
        auto stepped = gravityDocument();
        const double seconds = 0.5 * settleSteps * Gravity::kFrameSeconds; // half the settling
        double now = 0.0;
        int calls = 0;
        while (now < seconds) {
            const double tick = rate > 0.0 ? 1.0 / rate : jitter(random);
            now += tick;
            calls += ticked->advanceGravity(tick);
        }
        EXPECT_NEAR(calls, now / Gravity::kFrameSeconds, 1.0) << rate << " Hz";
        for (int k = 0; k < calls; ++k)
            stepped->stepGravity();
        EXPECT_EQ(ticked->hose(id)->points(), stepped->hose(id)->points()) << rate << " Hz";
        // On to rest: the settled shape, and nothing more owed or stepped.
        for (int k = 0; k < 100000 && ticked->gravityActive(); ++k)
            ticked->advanceGravity(rate > 0.0 ? 1.0 / rate : jitter(random));
        EXPECT_EQ(ticked->gravityState(id), Document::GravityState::Settled) << rate << " Hz";
        EXPECT_EQ(ticked->hose(id)->points(), settled->hose(id)->points()) << rate << " Hz";
        EXPECT_EQ(ticked->advanceGravity(0.1), 0) << rate << " Hz";
    }
    // A long pause adds at most 0.1 s (nine steps); a bad time adds nothing.
    auto paused = gravityDocument();
    EXPECT_EQ(paused->advanceGravity(5.0), 9);
    EXPECT_EQ(paused->advanceGravity(std::numeric_limits<double>::quiet_NaN()), 0);
    EXPECT_EQ(paused->advanceGravity(-1.0), 0);
    EXPECT_EQ(paused->advanceGravity(0.5 * Gravity::kFrameSeconds), 0);
    EXPECT_EQ(paused->advanceGravity(0.5 * Gravity::kFrameSeconds), 1);
}

TEST(DocumentGravity, SettlingAnOpenedProjectDoesNotMarkItModified)
{
    auto document = openTestRig();
    const std::string id = test::addCantilever(*document);
    document->undoStack()->push(gravityOn(*document, id));
    const auto folder = test::outputDir() / "gravity-open";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    document->save(folder / "cantilever.ctproj");

    Document reopened(roots());
    reopened.adopt(readProject(folder / "cantilever.ctproj", roots()));
    EXPECT_TRUE(reopened.gravityActive()) << "a loaded hose with gravity on settles";
    EXPECT_GT(stepUntilSettled(reopened), 0);
    EXPECT_FALSE(reopened.isModified());
    EXPECT_EQ(reopened.undoStack()->count(), 0);
}

TEST(DocumentGravity, SaveSettlesFirstAndAReloadReproducesTheShapeOnScreen)
{
    auto document = openTestRig();
    const std::string id = test::addCantilever(*document);
    document->undoStack()->push(gravityOn(*document, id));
    const std::vector<Vec3> authored = document->hose(id)->points();
    for (int i = 0; i < 3; ++i) // a half-way frame, as when the author saves at once
        document->stepGravity();
    ASSERT_EQ(document->gravityState(id), Document::GravityState::Settling);
    const auto folder = test::outputDir() / "gravity-save";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    document->save(folder / "saved.ctproj");
    EXPECT_EQ(document->gravityState(id), Document::GravityState::Settled)
        << "saving shows the settled shape the file reproduces";
    const std::vector<Vec3> onScreen = document->hose(id)->points();
    EXPECT_LT(test::lowestY(onScreen), test::lowestY(authored) - 0.1);
    EXPECT_EQ(document->hoseDefinition(id)->route,
              (std::vector<Vec3>{Vec3(-0.3, 0.21, -0.06), Vec3(-0.55, 0.21, -0.06)}))
        << "the file keeps the authored route";

    Document reopened(roots());
    reopened.adopt(readProject(folder / "saved.ctproj", roots()));
    EXPECT_TRUE(reopened.hoseDefinition(id)->gravity.enabled);
    EXPECT_EQ(reopened.hose(id)->points(), authored) << "built from the route";
    stepUntilSettled(reopened);
    EXPECT_EQ(reopened.hose(id)->points(), onScreen) << "deterministic: the same sag";
}

TEST(DocumentColliders, FlaggingAPartIsAnUndoStepThatIsSavedAndReloaded)
{
    auto document = openTestRig();
    const int floor = document->scene("rig")->findNode("/test-rig/floor_plate");
    ASSERT_GE(floor, 0);
    EXPECT_FALSE(document->isCollider("rig", floor));
    std::vector<ChangeEvent> events;
    QObject::connect(document.get(), &Document::changed,
                     [&](const ChangeEvent& event) { events.push_back(event); });
    expectExactUndo(*document, makeSetCollider(*document, {"rig", floor}, true));
    EXPECT_TRUE(document->isCollider("rig", floor));
    ASSERT_EQ(document->project().colliders.size(), 1u);
    EXPECT_EQ(document->project().colliders[0].node, "/test-rig/floor_plate");
    int colliderEvents = 0; // push, undo and redo each tell the views
    for (const ChangeEvent& event : events)
        colliderEvents += event.kind == ChangeEvent::Kind::CollidersChanged &&
                          event.sceneId == "rig" && event.node == floor;
    EXPECT_EQ(colliderEvents, 3);
    const int steps = document->undoStack()->count();
    document->undoStack()->push(makeSetCollider(*document, {"rig", floor}, true));
    EXPECT_EQ(document->project().colliders.size(), 1u) << "flagging twice lists it once";
    document->undoStack()->setIndex(steps);

    const auto folder = test::outputDir() / "colliders";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    document->save(folder / "colliders.ctproj");
    Document reopened(roots());
    reopened.adopt(readProject(folder / "colliders.ctproj", roots()));
    EXPECT_TRUE(reopened.isCollider("rig", floor));
    expectExactUndo(reopened, makeSetCollider(reopened, {"rig", floor}, false));
    EXPECT_FALSE(reopened.isCollider("rig", floor));
}

/// Drags point `point` of the live hose to `target` in ten steps (as mouse moves do), then
/// returns its surface's signed distance to `collider` (negative: inside) and cancels the drag.
double dragIntoAndMeasure(Document& document, const std::string& id, int point, const Vec3& target,
                          const MeshCollider& collider)
{
    const Vec3 start = document.hose(id)->point(point);
    for (int k = 1; k <= 10; ++k)
        static_cast<void>(document.dragHosePoint(id, point, start + (target - start) * (k / 10.0)));
    const Clearance c = clearance(*document.hose(id), collider);
    document.cancelHoseDrag(id);
    return c.found ? c.distance : 1.0;
}

TEST(DocumentColliders, ALiveHoseStaysOutsideAFlaggedPartAndGoesThroughWhenTheFlagIsUndone)
{
    auto document = openTestRig();
    const formats::ImportedScene& rig = *document->scene("rig");
    const int bracket = rig.findNode("/test-rig/bracket_right"); // right-return is fixed to it
    ASSERT_GE(bracket, 0);
    const std::string leftFeed = "left-feed", rightReturn = "right-return";
    ASSERT_TRUE(document->hose(leftFeed) && document->hose(rightReturn));
    EXPECT_TRUE(document->hoseColliders(leftFeed).empty());

    document->undoStack()->push(makeSetCollider(*document, {"rig", bracket}, true));
    ASSERT_EQ(document->hoseColliders(leftFeed).size(), 1u);
    EXPECT_TRUE(document->hoseColliders(rightReturn).empty()) << "its end sits in the bracket";
    const std::shared_ptr<const MeshCollider> box = document->hoseColliders(leftFeed)[0];

    // Move the bracket (4 x 20 x 6 cm) under left-feed's middle: the collider follows the pose.
    const int point = document->hose(leftFeed)->pointCount() / 2;
    const Vec3 middle = document->hose(leftFeed)->point(point);
    formats::Mat4 moved = document->nodeLocalTransform("rig", bracket);
    moved.block<3, 1>(0, 3) = Vec3(middle.x(), middle.y() - 0.125, middle.z()); // top 25 mm below
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", bracket}, moved));
    EXPECT_NEAR(box->worldBounds().max.y(), middle.y() - 0.025, 1e-6); // float vertices
    const Vec3 inside(middle.x(), middle.y() - 0.125, middle.z());     // the bracket's centre

    const double tolerance = CollisionOptions{}.tolerance;
    const double flagged = dragIntoAndMeasure(*document, leftFeed, point, inside, *box);
    EXPECT_GE(flagged, -tolerance - 1e-9) << "penetration beyond the tolerance";

    document->undoStack()->undo(); // the move
    document->undoStack()->undo(); // the flag: the old behaviour
    EXPECT_FALSE(document->isCollider("rig", bracket));
    EXPECT_TRUE(document->hoseColliders(leftFeed).empty());
    document->undoStack()->push(makeSetNodeTransform(*document, {"rig", bracket}, moved));
    const std::shared_ptr<MeshCollider> measured = // the same part at the same place
        formats::nodeCollider(rig, bracket, document->nodeWorldTransform("rig", bracket));
    ASSERT_TRUE(measured);
    const double unflagged = dragIntoAndMeasure(*document, leftFeed, point, inside, *measured);
    EXPECT_LT(unflagged, -0.005) << "without the flag the hose goes into the bracket";

    // Flagged again, now at the moved pose.
    document->undoStack()->push(makeSetCollider(*document, {"rig", bracket}, true));
    ASSERT_EQ(document->hoseColliders(leftFeed).size(), 1u);
    const double again = dragIntoAndMeasure(*document, leftFeed, point, inside,
                                            *document->hoseColliders(leftFeed)[0]);
    EXPECT_GE(again, -tolerance - 1e-9);
    std::cout << "[ colliders ] left-feed point " << point << " dragged to the bracket's centre: "
              << "flagged " << flagged << " m, unflagged " << unflagged << " m, flagged again "
              << again << " m (surface to bracket; tolerance " << tolerance << " m)\n";
}

TEST(DocumentGravity, TorsionAndGravityDirectionAreSavedAndReloaded)
{
    auto document = openTestRig();
    const std::string id = document->project().hoses[1].id;
    Torsion torsion;
    torsion.enabled = true;
    torsion.twistLimit = 10.0 * 3.14159265358979323846 / 180.0;
    expectExactUndo(*document, makeChangeHoseField(*document, id, &formats::HoseDefinition::torsion,
                                                   torsion, MergeId::HoseDefinition, "t"));
    Gravity gravity;
    gravity.direction = Vec3(0.0, 0.0, -1.0);
    expectExactUndo(*document, makeChangeHoseField(*document, id, &formats::HoseDefinition::gravity,
                                                   gravity, MergeId::HoseDefinition, "g"));
    EXPECT_TRUE(document->hose(id)->spec().torsion.enabled) << "the live hose has it";
    const auto folder = test::outputDir() / "torsion";
    std::filesystem::create_directories(folder / "scenes");
    std::filesystem::copy_file(samplesDir() / "scenes/test-rig.gltf",
                               folder / "scenes/test-rig.gltf",
                               std::filesystem::copy_options::overwrite_existing);
    document->save(folder / "torsion.ctproj");
    Document reopened(roots());
    reopened.adopt(readProject(folder / "torsion.ctproj", roots()));
    EXPECT_EQ(reopened.hoseDefinition(id)->torsion.twistLimit, torsion.twistLimit);
    EXPECT_TRUE(reopened.hoseDefinition(id)->torsion.enabled);
    EXPECT_EQ(reopened.hoseDefinition(id)->gravity.direction, gravity.direction);
    EXPECT_FALSE(reopened.hoseDefinition(id)->gravity.enabled);
}

} // namespace
} // namespace chaintube::editor
