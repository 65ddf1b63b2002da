// End-to-end tests of the real main window under xvfb-run (platform xcb, Mesa), driven with
// QTest mouse and key events: open a sample, grab-drag a hose, lay out a new hose by clicks on
// the scene, fix one end to a part, move the part (gizmo and numeric field), check the hose
// followed, undo everything, export and validate the written file. Screenshots go to the test
// output folder (CHAINTUBE_UPDATE_SCREENSHOTS=1: to editor/screenshots).
#include "main_window_test.h"

#include "chaintube/editor/commands.h"
#include "chaintube/editor/export_integration.h"
#include "chaintube/editor/route_layout.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/route.h"
#include "chaintube/test_support/hose_checks.h"
#include "export_dialog.h"
#include "import_dialog.h"
#include "main_window.h"
#include "problems_panel.h"
#include "properties_panel.h"
#include "viewport.h"

#include <Eigen/Geometry>
#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFileDialog>
#include <QGroupBox>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QMouseEvent>
#include <QProgressDialog>
#include <QPushButton>
#include <QRadioButton>
#include <QRegularExpression>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSlider>
#include <QSpinBox>
#include <QStatusBar>
#include <QTest>
#include <QTimer>
#include <QTreeWidget>
#include <QUndoView>
#include <QWheelEvent>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <set>
#include <vector>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;
using namespace test;

TEST_F(MainWindowTest, LayOutFixMoveUndoAndExportOnTheTestRig)
{
    const QString project = qtPath(copyOfTestRig("e2e"));
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    settle();
    const std::string initialState = document.stateFingerprint();
    const auto initialPoints = allPoints(document);

    // 1. Grab a point of the left hose and drag it upwards: the hose deforms, one undo step.
    {
        const Vec3 before = document.hose("left-feed")->point(8);
        const QPoint at = viewport.toWidget(before);
        drag(&viewport, at, at + QPoint(0, -40));
        EXPECT_EQ(document.selection().hoseId, "left-feed");
        EXPECT_GT((document.hose("left-feed")->point(8) - before).norm(), 0.01);
        EXPECT_EQ(document.undoStack()->count(), 1);
    }

    // 2. Lay out a new hose by clicks: on top of the valve, then two spots on the floor plate
    //    in front of it; Enter finishes.
    auto valveTop = topHits("/test-rig/valve");
    auto floor = topHits("/test-rig/floor_plate");
    ASSERT_FALSE(valveTop.empty());
    std::vector<std::pair<QPoint, ScenePickHit>> front;
    for (const auto& hit : floor)
        if (hit.second.point.z() > 0.2 && std::abs(hit.second.point.x()) < 0.3)
            front.push_back(hit);
    ASSERT_GE(front.size(), 2u);
    std::sort(front.begin(), front.end(),
              [](const auto& a, const auto& b) { return a.second.point.x() < b.second.point.x(); });
    // The valve spot farthest (on screen) from the hoses already fixed to the valve.
    auto clearance = [&](const QPoint& p) {
        double nearest = 1e9;
        for (const auto& hose : document.project().hoses)
            for (const Vec3& point : document.hose(hose.id)->points()) {
                const QPoint q = viewport.toWidget(point);
                nearest =
                    std::min(nearest, std::hypot(double(p.x() - q.x()), double(p.y() - q.y())));
            }
        return nearest;
    };
    const auto& first =
        *std::max_element(valveTop.begin(), valveTop.end(), [&](const auto& a, const auto& b) {
            return clearance(a.first) < clearance(b.first);
        });
    // On to the floor in front of the valve, then along it to the right: turns the hose's
    // 100 mm bend radius can follow on legs this long.
    const auto& middle =
        *std::min_element(front.begin(), front.end(), [&](const auto& a, const auto& b) {
            const double x = first.second.point.x() + 0.15;
            return std::abs(a.second.point.x() - x) < std::abs(b.second.point.x() - x);
        });
    const std::vector<std::pair<QPoint, ScenePickHit>> clicks = {first, middle, front.back()};
    QTest::keyClick(&viewport, Qt::Key_N);
    ASSERT_EQ(viewport.mode(), Viewport::Mode::LayRoute) << "shortcut N starts a new hose";
    for (const auto& click : clicks)
        QTest::mouseClick(&viewport, Qt::LeftButton, {}, click.first);
    ASSERT_EQ(viewport.pendingRoute().size(), 3u);
    takeKeys();
    QTest::keyClick(&viewport, Qt::Key_Return);
    settle();
    ASSERT_EQ(document.hoseCount(), 3) << m_errors.join('\n').toStdString();
    const std::string newId = document.project().hoses.back().id;
    const auto& route = document.hoseDefinition(newId)->route;
    ASSERT_EQ(route.size(), 3u);
    // The test rig's size gives a 20 mm hose; each route point lies out of the surface that
    // was clicked, along its normal, by the hose's radius plus the 5 mm clearance.
    EXPECT_DOUBLE_EQ(document.hoseDefinition(newId)->outerDiameter, 0.02);
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR((route[i] - clicks[i].second.point).norm(), 0.015, 2e-6);
        EXPECT_NEAR((route[i] - clicks[i].second.point).normalized().dot(clicks[i].second.normal),
                    1.0, 1e-9);
    }
    ASSERT_TRUE(document.hose(newId));

    // 3. Fix the start of the new hose to the valve: click its first axis point, extend the
    //    range to point 1, choose the valve in the scene tree, press "Fix to part".
    // (Axis point 0 lies under route point 0's handle: click point 1, then widen the range.)
    QTest::mouseClick(&viewport, Qt::LeftButton, {},
                      viewport.toWidget(document.hose(newId)->point(1)));
    ASSERT_EQ(document.selection().hoseId, newId);
    EXPECT_EQ(document.selection().rangeFirst, 1);
    clickTreeItem("valve");
    ASSERT_EQ(document.selection().node, document.scene("rig")->findNode("/test-rig/valve"));
    ASSERT_EQ(document.selection().hoseId, newId) << "choosing a part keeps the hose";
    m_window->findChild<QSpinBox*>("fixFirst")->setValue(0);
    m_window->findChild<QSpinBox*>("fixLast")->setValue(1);
    EXPECT_EQ(document.selection().rangeFirst, 0);
    EXPECT_EQ(document.selection().rangeLast, 1);
    QTest::mouseClick(m_window->findChild<QPushButton*>("fixButton"), Qt::LeftButton);
    settle();
    ASSERT_EQ(document.hoseDefinition(newId)->attachments.size(), 1u)
        << m_window->properties().lastRefusal().toStdString();
    EXPECT_TRUE(document.hose(newId)->isFixed(0));
    EXPECT_TRUE(document.hose(newId)->isFixed(1));
    // Fixed to the valve, the hose is not checked against it; its far end keeps the
    // clearance from the floor plate it was clicked on: neither is listed. No distance reads
    // as a negative "from" ("-0.0 mm from").
    m_window->problems().refreshNow();
    for (const Problem& problem : m_window->problems().problems()) {
        EXPECT_FALSE(problem.hoseId == newId && problem.text.contains("/test-rig/valve"))
            << problem.text.toStdString();
        EXPECT_FALSE(problem.hoseId == newId && problem.text.contains("/test-rig/floor_plate"))
            << problem.text.toStdString();
        EXPECT_FALSE(problem.text.contains(QRegularExpression(" -[0-9]")))
            << problem.text.toStdString();
    }
    screenshot("editor-test-rig.png");

    // 4. Move the valve with the gizmo's X arrow: the fixed end follows rigidly.
    const int valve = document.scene("rig")->findNode("/test-rig/valve");
    const Vec3 valveBefore = document.nodeWorldFrame("rig", valve).translation;
    const Vec3 startBefore = document.hose(newId)->point(0);
    const int stepsBefore = document.undoStack()->count();
    const double length = Renderer::gizmoLength(viewport.camera());
    const Vec3 gizmo = document.partCentre("rig", valve); // the gizmo sits at the part's centre
    const QPoint a = viewport.toWidget(gizmo);
    const QPoint b = viewport.toWidget(gizmo + length * Vec3::UnitX());
    const QPointF direction = QPointF(b - a) / std::hypot(b.x() - a.x(), b.y() - a.y());
    const QPoint grip = a + (b - a) * 0.8;
    drag(&viewport, grip, grip + (direction * 60).toPoint());
    const Vec3 valveAfter = document.nodeWorldFrame("rig", valve).translation;
    const Vec3 shift = valveAfter - valveBefore;
    EXPECT_GT(shift.x(), 0.02) << "the gizmo moved the valve along +X";
    EXPECT_NEAR(shift.y(), 0.0, 1e-9);
    EXPECT_NEAR(shift.z(), 0.0, 1e-9);
    EXPECT_EQ(document.undoStack()->count(), stepsBefore + 1) << "a gizmo drag is one step";
    EXPECT_EQ(document.undoStack()->undoText(), "Move valve");
    EXPECT_NEAR((document.hose(newId)->point(0) - (startBefore + shift)).norm(), 0.0, 1e-6)
        << "the fixed end followed the valve";

    // 5. …and with the numeric field: 25 mm along Z.
    auto* z = m_window->findChild<QDoubleSpinBox*>("partTranslationZ");
    ASSERT_TRUE(z);
    z->setValue(z->value() + 25.0);
    settle();
    EXPECT_NEAR((document.hose(newId)->point(0) - (startBefore + shift + Vec3(0, 0, 0.025))).norm(),
                0.0, 1e-6);
    // (The field shows micrometres; the file's float position is not a whole number of them.)
    EXPECT_NEAR(document.nodeWorldFrame("rig", valve).translation.z(), valveBefore.z() + 0.025,
                1e-6);

    // 6. Undo everything with Ctrl+Z: exactly the opened project again.
    int guard = 0;
    while (document.undoStack()->canUndo() && guard++ < 50)
        QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document.undoStack()->index(), 0);
    EXPECT_EQ(initialState, document.stateFingerprint());
    EXPECT_EQ(initialPoints, allPoints(document));
    EXPECT_FALSE(document.isModified());

    // 7. Export through the dialog (the exporter library's exportProject, as the CLI).
    if (!exportAvailable()) {
        std::printf("export library not built: export step skipped\n");
        return;
    }
    const fs::path output = outputDir() / "e2e" / "rig.glb";
    fs::remove(output);
    m_window->action("actionExport")->trigger();
    m_window->exportDialog().setOutputPath(QString::fromStdString(output.string()));
    ASSERT_TRUE(m_window->exportDialog().runExport())
        << m_window->exportDialog().summaryText().toStdString();
    EXPECT_TRUE(m_window->exportDialog().summaryText().contains("2 hoses"))
        << m_window->exportDialog().summaryText().toStdString();
    // Each file written is listed with its size: the glTF and the descriptor apart.
    const QString summary = m_window->exportDialog().summaryText();
    EXPECT_TRUE(
        summary.contains(QRegularExpression("rig\\.glb  [0-9.]+ (KB|MB|bytes)  \\(glTF\\)")))
        << summary.toStdString();
    if (fs::exists(output.parent_path() / "rig.hoses.json")) {
        EXPECT_TRUE(summary.contains(
            QRegularExpression("rig\\.hoses\\.json  [0-9.]+ (KB|MB|bytes)  \\(hose descriptor\\)")))
            << summary.toStdString();
    }
    const QJsonObject gltf = readGlb(output);
    EXPECT_EQ(gltf["asset"].toObject()["version"].toString(), "2.0");
    EXPECT_EQ(gltf["skins"].toArray().size(), 2) << "one skin per hose";
    QStringList nodeNames;
    for (const auto& node : gltf["nodes"].toArray())
        nodeNames << node.toObject()["name"].toString();
    EXPECT_TRUE(nodeNames.contains("valve")) << nodeNames.join(',').toStdString();
    EXPECT_TRUE(gltf["extensionsUsed"].toArray().contains(QJsonValue("CHAINTUBE_hose_rig")));
}

TEST_F(MainWindowTest, EngineSceneLayOutFixAndMove)
{
    if (!haveScenes())
        GTEST_SKIP() << "CHAINTUBE_SCENES_DIR has no 2CylinderEngine.glb: engine test skipped";
    ASSERT_TRUE(
        m_window->openFile(QString::fromStdString((samplesDir() / "engine.ctproj").string())))
        << m_errors.join('\n').toStdString();
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    settle();
    const std::string initialState = document.stateFingerprint();
    const int hosesBefore = document.hoseCount();
    // Click three points on engine parts spread over the view.
    std::vector<std::pair<QPoint, ScenePickHit>> hits;
    for (QPoint p : {QPoint(viewport.width() * 35 / 100, viewport.height() / 2),
                     QPoint(viewport.width() / 2, viewport.height() * 40 / 100),
                     QPoint(viewport.width() * 65 / 100, viewport.height() / 2)}) {
        // Search around each spot for a surface.
        ScenePickHit hit;
        bool found = false;
        for (int r = 0; r < 200 && !found; r += 6)
            for (QPoint d : {QPoint(r, 0), QPoint(-r, 0), QPoint(0, r), QPoint(0, -r)})
                if (!found && viewport.pickScene(p + d, &hit)) {
                    hits.push_back({p + d, hit});
                    found = true;
                }
    }
    ASSERT_EQ(hits.size(), 3u);
    m_window->action("actionNewHose")->trigger();
    for (const auto& hit : hits)
        QTest::mouseClick(&viewport, Qt::LeftButton, {}, hit.first);
    takeKeys();
    QTest::keyClick(&viewport, Qt::Key_Return);
    settle();
    ASSERT_EQ(document.hoseCount(), hosesBefore + 1) << m_errors.join('\n').toStdString();
    const std::string id = document.project().hoses.back().id;
    // Fix the first point to the part that was clicked first, then move that part.
    Selection selection = document.selection();
    selection.hoseId = id;
    selection.rangeFirst = selection.rangeLast = 0;
    selection.sceneId = hits[0].second.sceneId;
    selection.node = hits[0].second.node;
    document.setSelection(selection);
    QTest::mouseClick(m_window->findChild<QPushButton*>("fixButton"), Qt::LeftButton);
    ASSERT_EQ(document.hoseDefinition(id)->attachments.size(), 1u)
        << m_window->properties().lastRefusal().toStdString();
    const Vec3 before = document.hose(id)->point(0);
    const Vec3 partBefore = document.nodeWorldFrame(selection.sceneId, selection.node).translation;
    auto* y = m_window->findChild<QDoubleSpinBox*>("partTranslationY");
    y->setValue(y->value() + 30.0);
    settle();
    const Vec3 partShift =
        document.nodeWorldFrame(selection.sceneId, selection.node).translation - partBefore;
    EXPECT_GT(partShift.norm(), 1e-4);
    EXPECT_NEAR((document.hose(id)->point(0) - before - partShift).norm(), 0.0, 1e-6);
    screenshot("editor-engine.png");
    while (document.undoStack()->canUndo())
        document.undoStack()->undo();
    EXPECT_EQ(initialState, document.stateFingerprint());
}

/// Least distance (metres) from the axis of live hose `hoseId` (its segments, not only its
/// points) to the triangles of scene node `path`: the hose's clearance plus its outer radius.
double axisDistanceToNode(const Document& document, const std::string& hoseId,
                          const std::string& sceneId, const std::string& path)
{
    const formats::ImportedScene* scene = document.scene(sceneId);
    const Hose* hose = document.hose(hoseId);
    if (!scene || !hose) return -1.0;
    const int node = scene->findNode(path);
    if (node < 0) return -1.0;
    const auto collider =
        formats::nodeCollider(*scene, node, document.nodeWorldTransform(sceneId, node));
    if (!collider) return -1.0;
    return clearance(*hose, *collider).distance + hose->outerRadius();
}

/// Four clicks across the back half of the test rig's floor plate, scaled by `scale` (the
/// scene's metres per unit): left to right, alternately nearer the brackets and nearer the
/// back edge, clear of the brackets by more than a hose's radius and clearance.
std::vector<std::pair<QPoint, ScenePickHit>>
backOfTheFloor(const std::vector<std::pair<QPoint, ScenePickHit>>& floorHits, double scale)
{
    std::vector<std::pair<QPoint, ScenePickHit>> clicks;
    for (int i = 0; i < 4; ++i) {
        const Vec3 target(scale * (-0.3 + 0.2 * i), 0.0, scale * (i % 2 == 0 ? -0.12 : -0.21));
        const auto nearest =
            std::min_element(floorHits.begin(), floorHits.end(), [&](const auto& a, const auto& b) {
                return (a.second.point - target).cwiseProduct(Vec3(1, 0, 1)).norm() <
                       (b.second.point - target).cwiseProduct(Vec3(1, 0, 1)).norm();
            });
        if (nearest != floorHits.end()) clicks.push_back(*nearest);
    }
    return clicks;
}

TEST_F(MainWindowTest, ARouteClickedOnASurfaceKeepsTheNewHoseOutOfThePartAtEveryScale)
{
    // The test rig's scene read with 0.25, 1 and 2.5 metres per unit: a 0.24 m assembly, the
    // 0.97 m rig and a 2.4 m scene (bounding-box diagonals). Each gets a new hose laid out by
    // four clicks on the floor plate, as an author makes them.
    struct Case
    {
        double scale;
        double diameter; ///< the default outer diameter the rule gives (route_layout.h)
    };
    for (const Case& scaleCase : {Case{0.25, 0.005}, Case{1.0, 0.020}, Case{2.5, 0.050}}) {
        SCOPED_TRACE("metres per unit " + std::to_string(scaleCase.scale));
        QJsonObject scene{{"id", "rig"}, {"path", "scenes/test-rig.gltf"}};
        scene["import"] = QJsonObject{{"metresPerUnit", scaleCase.scale},
                                      {"chordalTolerance", 1e-4},
                                      {"angularTolerance", 0.5}};
        const std::string folder = "route-on-surface-" + std::to_string(int(scaleCase.scale * 100));
        ASSERT_TRUE(m_window->openFile(writeProject(folder, scene)))
            << m_errors.join('\n').toStdString();
        Document& document = m_window->document();
        Viewport& viewport = m_window->viewport();
        QTest::keyClick(&viewport, Qt::Key_Home); // frame everything
        settle();
        ScenePicker picker;
        picker.update(document);
        const double diagonal = (picker.bounds().max - picker.bounds().min).norm();
        EXPECT_DOUBLE_EQ(defaultHoseDiameter(picker.bounds()), scaleCase.diameter)
            << "scene diagonal " << diagonal << " m";

        const auto clicks = backOfTheFloor(topHits("/test-rig/floor_plate"), scaleCase.scale);
        ASSERT_EQ(clicks.size(), 4u);
        const int steps = document.undoStack()->count();
        QTest::keyClick(&viewport, Qt::Key_N);
        ASSERT_EQ(viewport.mode(), Viewport::Mode::LayRoute);
        EXPECT_DOUBLE_EQ(viewport.newHoseDiameter(), scaleCase.diameter);
        EXPECT_TRUE(m_window->statusBar()->currentMessage().contains(
            QString("New hose (%1 mm)").arg(scaleCase.diameter * 1000.0, 0, 'g', 3)))
            << m_window->statusBar()->currentMessage().toStdString();
        for (const auto& click : clicks)
            QTest::mouseClick(&viewport, Qt::LeftButton, {}, click.first);
        ASSERT_EQ(viewport.pendingRoute().size(), 4u);
        takeKeys();
        QTest::keyClick(&viewport, Qt::Key_Return);
        settle();
        ASSERT_EQ(document.hoseCount(), 1) << m_errors.join('\n').toStdString();
        EXPECT_EQ(document.undoStack()->count(), steps + 1) << "one undo step for the hose";
        const std::string id = document.project().hoses.back().id;
        const formats::HoseDefinition& definition = *document.hoseDefinition(id);

        // Its size: the default diameter, a bend radius of five diameters (the "PVC hose"
        // preset is kept where it has that: at 20 mm), segments of at most half of it.
        const double radius = 0.5 * scaleCase.diameter;
        const double clearanceMetres = m_window->problems().clearanceThreshold()->value() / 1000.0;
        EXPECT_DOUBLE_EQ(clearanceMetres, 0.005);
        EXPECT_DOUBLE_EQ(definition.outerDiameter, scaleCase.diameter);
        const Material material = document.project().materialOf(definition);
        EXPECT_EQ(material.bendLimit.kind, BendLimit::Kind::MinBendRadius);
        EXPECT_DOUBLE_EQ(material.bendLimit.value, 5.0 * scaleCase.diameter);
        EXPECT_DOUBLE_EQ(material.expansionCoefficient, 0.05);
        EXPECT_EQ(std::holds_alternative<formats::PresetName>(definition.material),
                  scaleCase.diameter == 0.020);
        const Hose& hose = *document.hose(id);
        EXPECT_LE(hose.restLength(0), std::min(0.03, 2.5 * scaleCase.diameter) * 1.05);

        // Every route point is out of the surface clicked, along its normal (up), by the
        // hose's outer radius plus the clearance.
        ASSERT_EQ(definition.route.size(), 4u);
        for (size_t i = 0; i < 4; ++i) {
            const Vec3 out = definition.route[i] - clicks[i].second.point;
            EXPECT_NEAR(out.y(), radius + clearanceMetres, 2e-6) << i;
            EXPECT_NEAR(out.cwiseProduct(Vec3(1, 0, 1)).norm(), 0.0, 1e-9) << i;
        }
        // The hose: its ends are the route's; its axis keeps radius + clearance from the floor
        // plate everywhere, so the
        // clearance check (5 mm) lists nothing for it.
        EXPECT_NEAR((hose.point(0) - definition.route.front()).norm(), 0.0, 1e-9);
        EXPECT_NEAR((hose.point(hose.segmentCount()) - definition.route.back()).norm(), 0.0, 1e-6);
        const double axisToFloor = axisDistanceToNode(document, id, "rig", "/test-rig/floor_plate");
        EXPECT_GE(axisToFloor, radius + clearanceMetres - 1e-7);
        std::printf("metres per unit %.2f: scene diagonal %.3f m, new hose %.0f mm, bend radius "
                    "%.0f mm, %d segments; axis to the floor plate %.4f mm (radius + clearance "
                    "%.4f mm)\n",
                    scaleCase.scale, diagonal, definition.outerDiameter * 1000.0,
                    material.bendLimit.value * 1000.0, hose.segmentCount(), axisToFloor * 1000.0,
                    (radius + clearanceMetres) * 1000.0);
        m_window->problems().refreshNow();
        for (const Problem& problem : m_window->problems().problems())
            EXPECT_NE(problem.hoseId, id) << problem.text.toStdString();
        if (scaleCase.scale == 0.25) screenshot("editor-route-on-surface.png");

        // Undo removes the hose in one step; redo brings it back as it was.
        const std::vector<Vec3> points = hose.points();
        QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
        settle();
        EXPECT_EQ(document.hoseCount(), 0);
        EXPECT_EQ(document.undoStack()->count(), steps + 1);
        EXPECT_EQ(document.undoStack()->index(), steps);
        QTest::keyClick(&viewport, Qt::Key_Y, Qt::ControlModifier);
        settle();
        ASSERT_EQ(document.hoseCount(), 1);
        EXPECT_EQ(document.hose(id)->points(), points);
        EXPECT_DOUBLE_EQ(document.hoseDefinition(id)->outerDiameter, scaleCase.diameter);
    }
}

TEST_F(MainWindowTest, FourClicksOnTheStepBracketLayAHoseOutsideTheBracket)
{
    std::shared_ptr<MeshCollider> bracketCollider;
    openStepBracketToLayARoute("route-on-step-bracket", &bracketCollider);
    if (IsSkipped() || HasFatalFailure()) return;
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    const std::string& bracket = kStepBracket;
    const double diameter = viewport.newHoseDiameter();
    const double radius = 0.5 * diameter;
    const double clearanceMetres = m_window->problems().clearanceThreshold()->value() / 1000.0;

    // The bracket's flange lying on the plate: the upward faces at the most common height,
    // where the rest of the bracket (its upright, the edges of its holes) is farther from the
    // spot than the hose's radius plus the clearance, as an author clicks along a flange.
    auto flange = topHits(bracket);
    ASSERT_FALSE(flange.empty());
    std::map<long, int> heights;
    for (const auto& hit : flange)
        ++heights[std::lround(hit.second.point.y() * 1e4)];
    const long flangeTop =
        std::max_element(heights.begin(), heights.end(), [](const auto& a, const auto& b) {
            return a.second < b.second;
        })->first;
    std::erase_if(flange, [&](const auto& hit) {
        const Vec3 out = hit.second.point + (radius + clearanceMetres) * hit.second.normal;
        return std::lround(hit.second.point.y() * 1e4) != flangeTop ||
               bracketCollider->closestToPoint(out).distance < radius + clearanceMetres - 1e-9;
    });
    ASSERT_GE(flange.size(), 4u);
    // Four clicks spread over it, left to right on the screen.
    std::sort(flange.begin(), flange.end(),
              [](const auto& a, const auto& b) { return a.first.x() < b.first.x(); });
    const std::vector<std::pair<QPoint, ScenePickHit>> clicks = {
        flange[0], flange[flange.size() / 3], flange[2 * flange.size() / 3], flange.back()};
    for (const auto& click : clicks)
        QTest::mouseClick(&viewport, Qt::LeftButton, {}, click.first);
    ASSERT_EQ(viewport.pendingRoute().size(), 4u);
    takeKeys();
    QTest::keyClick(&viewport, Qt::Key_Return);
    settle();
    ASSERT_EQ(document.hoseCount(), 1) << m_errors.join('\n').toStdString();
    const std::string id = document.project().hoses.back().id;
    ScenePicker picker;
    picker.update(document);
    EXPECT_DOUBLE_EQ(diameter, defaultHoseDiameter(picker.bounds()));
    EXPECT_LT(diameter, 0.02) << "a 0.2 m assembly gets a smaller hose than the 1 m test rig";
    const double axisToBracket = axisDistanceToNode(document, id, "as1", bracket);
    std::printf("STEP bracket: scene diagonal %.3f m, new hose %.0f mm; axis to the l-bracket "
                "%.4f mm (radius + clearance %.4f mm)\n",
                (picker.bounds().max - picker.bounds().min).norm(), diameter * 1000.0,
                axisToBracket * 1000.0, (radius + clearanceMetres) * 1000.0);
    EXPECT_GE(axisToBracket, radius + clearanceMetres - 1e-6);
    m_window->problems().refreshNow();
    for (const Problem& problem : m_window->problems().problems())
        EXPECT_FALSE(problem.hoseId == id && problem.text.contains("l-bracket_1"))
            << problem.text.toStdString();
    screenshot("editor-route-on-step-bracket.png");
}

// Route points clicked on the bracket's flange next to its upright (where the flange's own
// normal would leave the point nearer the upright than the hose's radius plus the clearance)
// are moved on until every surface of the scene keeps that distance.
TEST_F(MainWindowTest, ARouteClickedPastTheValveIsValidWhenLaid)
{
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("route-valid-when-laid"))));
    Document& document = m_window->document();
    settle();
    // Along the floor past the valve: the leg between the middle clicks passes 5.5 mm from the
    // valve's corner, which reaches to z = 0.1995 m (a hose of 10 mm radius would run into it).
    const std::vector<Vec3> clicked = layRouteOnTheFloor(
        {Vec3(-0.35, 0, 0.0), Vec3(-0.2, 0, 0.205), Vec3(0.2, 0, 0.205), Vec3(0.35, 0, 0.0)});
    ASSERT_EQ(clicked.size(), 4u);
    ASSERT_EQ(document.hoseCount(), 3) << m_errors.join('\n').toStdString();
    const std::string id = document.project().hoses.back().id;
    const formats::HoseDefinition& definition = *document.hoseDefinition(id);
    const Hose& hose = *document.hose(id);
    // The clicked points are kept, in order; points were added between them.
    std::vector<Vec3> kept;
    for (const Vec3& p : definition.route)
        if (std::find(clicked.begin(), clicked.end(), p) != clicked.end()) kept.push_back(p);
    EXPECT_EQ(kept, clicked);
    EXPECT_GT(definition.route.size(), clicked.size()) << "route points were added";
    // Valid as laid: every segment in its band, every bend within the limit, clear of every
    // part by the clearance, and no problem listed for it.
    const HoseMetrics m = measure(hose);
    EXPECT_TRUE(m.bendBelowMinimum.empty()) << m.smallestBendRadius;
    EXPECT_LE(m.angleViolation, 1e-9);
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const double length = (hose.point(s + 1) - hose.point(s)).norm();
        EXPECT_GE(length, hose.minLength(s) * (1 - 1e-9)) << "segment " << s;
        EXPECT_LE(length, hose.maxLength(s) * (1 + 1e-9)) << "segment " << s;
    }
    const double wanted = 0.5 * definition.outerDiameter +
                          m_window->problems().clearanceThreshold()->value() / 1000.0;
    ScenePicker picker;
    picker.update(document);
    double smallest = wanted;
    for (int i = 0; i < hose.pointCount(); ++i) {
        Vec3 onSurface;
        if (picker.nearest(hose.point(i), wanted, &onSurface))
            smallest = std::min(smallest, (hose.point(i) - onSurface).norm());
    }
    std::printf("route of %zu clicks laid with %zu points; the axis keeps %.3f mm from every "
                "part (%.3f wanted)\n",
                clicked.size(), definition.route.size(), smallest * 1000.0, wanted * 1000.0);
    EXPECT_GE(smallest, wanted * (1 - 1e-3));
    m_window->problems().refreshNow();
    for (const Problem& problem : m_window->problems().problems())
        EXPECT_NE(problem.hoseId, id) << problem.text.toStdString();
    // One undo step removes it.
    QTest::keyClick(m_window.get(), Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document.hoseCount(), 2);
}

TEST_F(MainWindowTest, ACornerTheClicksLeaveTooTightIsNamedByItsRoutePoint)
{
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("route-tight-corner"))));
    Document& document = m_window->document();
    settle();
    // Along the floor in front of the valve, then 5 cm on and back: no 100 mm bend fits at the
    // hairpin's two corners (route points 2 and 3).
    ASSERT_EQ(layRouteOnTheFloor({Vec3(-0.3, 0, 0.22), Vec3(0.25, 0, 0.22), Vec3(0.28, 0, 0.18),
                                  Vec3(-0.2, 0, 0.18)})
                  .size(),
              4u);
    ASSERT_EQ(document.hoseCount(), 3) << m_errors.join('\n').toStdString();
    const std::string id = document.project().hoses.back().id;
    m_window->problems().refreshNow();
    QStringList named;
    for (const Problem& problem : m_window->problems().problems())
        if (problem.hoseId == id && problem.text.contains("kinked")) named << problem.text;
    ASSERT_FALSE(named.isEmpty()) << "the hairpin is listed";
    for (const QString& text : named) {
        std::printf("%s\n", text.toStdString().c_str());
        EXPECT_TRUE(text.contains("route point 2 is too tight") ||
                    text.contains("route point 3 is too tight"))
            << text.toStdString();
    }
}

TEST_F(MainWindowTest, RoutePointsClickedNextToTheBracketsUprightKeepTheClearanceFromEveryFace)
{
    std::shared_ptr<MeshCollider> bracketCollider;
    openStepBracketToLayARoute("route-in-bracket-corner", &bracketCollider);
    if (IsSkipped() || HasFatalFailure()) return;
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    const std::string& bracket = kStepBracket;
    const double wanted = 0.5 * viewport.newHoseDiameter() +
                          m_window->problems().clearanceThreshold()->value() / 1000.0;
    // Upward hits on the bracket whose point out along the normal is too near the bracket.
    auto corner = topHits(bracket);
    std::erase_if(corner, [&](const auto& hit) {
        const Vec3 out = hit.second.point + wanted * hit.second.normal;
        return hit.second.normal.y() < 0.9 ||
               !(bracketCollider->closestToPoint(out).distance < wanted - 1e-4);
    });
    ASSERT_GE(corner.size(), 2u) << "no flange spot next to the upright was found";
    std::sort(corner.begin(), corner.end(),
              [](const auto& a, const auto& b) { return a.first.x() < b.first.x(); });
    const std::vector<std::pair<QPoint, ScenePickHit>> clicks = {corner.front(), corner.back()};
    for (const auto& click : clicks)
        QTest::mouseClick(&viewport, Qt::LeftButton, {}, click.first);
    ASSERT_EQ(viewport.pendingRoute().size(), 2u);
    ScenePicker picker;
    picker.update(document);
    for (size_t i = 0; i < clicks.size(); ++i) {
        const Vec3 point = viewport.pendingRoute()[i];
        const Vec3 naive = clicks[i].second.point + wanted * clicks[i].second.normal;
        const double before = bracketCollider->closestToPoint(naive).distance;
        const double after = bracketCollider->closestToPoint(point).distance;
        Vec3 nearest;
        const bool anyNearer = picker.nearest(point, wanted - 1e-6, &nearest);
        std::printf("corner click %zu: out along the normal %.3f mm from the bracket, placed "
                    "%.4f mm (wanted %.4f mm)\n",
                    i, before * 1000.0, after * 1000.0, wanted * 1000.0);
        EXPECT_LT(before, wanted - 1e-4) << "the click is next to another face";
        EXPECT_GE(after, wanted - 1e-6) << "click " << i;
        EXPECT_FALSE(anyNearer) << "click " << i << ": a surface at "
                                << (nearest - point).norm() * 1000.0 << " mm";
    }
    takeKeys();
    QTest::keyClick(&viewport, Qt::Key_Return);
    settle();
    ASSERT_EQ(document.hoseCount(), 1) << m_errors.join('\n').toStdString();
    screenshot("editor-route-in-corner.png");
}

TEST_F(MainWindowTest, RotateGizmoTurnsAPartInSnappedStepsAndTheHosesFollow)
{
    const QString project = qtPath(copyOfTestRig("rotate"));
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    settle();
    const auto initialPoints = allPoints(document);
    clickTreeItem("valve");
    const int valve = document.scene("rig")->findNode("/test-rig/valve");
    ASSERT_EQ(document.selection().node, valve);
    settle();

    // The valve's frame and the hose points fixed under it (right-return's last point is
    // fixed to the valve, left-feed's points 15–16 to the valve's inlet child). The gizmo sits
    // at the valve's bounding-box centre and turns it about that point.
    const Frame before = document.nodeWorldFrame("rig", valve);
    const Vec3 centre = document.partCentre("rig", valve);
    const Vec3 rightEnd = document.hose("right-return")->points().back();
    const Vec3 leftEnd = document.hose("left-feed")->point(16);
    const Vec3 leftMiddle = document.hose("left-feed")->point(8);

    // Drag along the ring about Y (the one lying flat) from one side of the centre over a
    // quarter turn on screen, holding Ctrl: a snapped rotation about +Y or −Y.
    const double radius = Renderer::gizmoRingRadius(viewport.camera());
    const std::vector<Vec3> ring = Renderer::gizmoRing(centre, 1, radius, 64);
    // Start on the ring where no arrow is near (between +X and +Z: index 8 of 64 = 45°).
    std::vector<QPoint> path;
    for (int i = 8; i <= 24; i += 2)
        path.push_back(viewport.toWidget(ring[static_cast<size_t>(i)]));
    const int stepsBefore = document.undoStack()->count();
    // (No QTest::mouseMove before the press: without a button held it moves the real X
    // pointer, whose motion event would arrive later and undo the drag's angle.)
    QTest::mousePress(&viewport, Qt::LeftButton, Qt::ControlModifier, path.front());
    for (const QPoint& p : path) {
        // (QTest::mouseMove sends no modifiers: Ctrl is held through the whole drag.)
        QMouseEvent move(QEvent::MouseMove, QPointF(p), viewport.mapToGlobal(QPointF(p)),
                         Qt::NoButton, Qt::LeftButton, Qt::ControlModifier);
        QApplication::sendEvent(&viewport, &move);
    }
    settle();
    screenshot("editor-rotate.png"); // while the ring is held: highlighted
    QTest::mouseRelease(&viewport, Qt::LeftButton, Qt::ControlModifier, path.back());
    settle();

    EXPECT_EQ(document.undoStack()->count(), stepsBefore + 1) << "a rotate drag is one step";
    EXPECT_EQ(document.undoStack()->undoText(), "Rotate valve");
    const Frame after = document.nodeWorldFrame("rig", valve);
    const Eigen::AngleAxisd turn(after.rotation * before.rotation.inverse());
    EXPECT_NEAR(
        (after.translation - (centre + turn.toRotationMatrix() * (before.translation - centre)))
            .norm(),
        0.0, 1e-9)
        << "rotation about the part's centre";
    EXPECT_NEAR((document.partCentre("rig", valve) - centre).norm(), 0.0, 1e-9)
        << "the centre stays where it is";
    const double degrees = turn.angle() * 180.0 / 3.14159265358979323846;
    EXPECT_GT(degrees, 40.0) << "a quarter turn of the ring on screen turns the part";
    EXPECT_NEAR(std::remainder(degrees, 15.0), 0.0, 1e-6) << degrees << "° is not a 15° step";
    EXPECT_GT(std::abs(turn.axis().y()), 1.0 - 1e-9) << "about the Y axis";

    // The fixed points turned rigidly with the valve, about its centre; the free middle of the
    // left hose moved with them.
    const Eigen::Matrix3d rotation = turn.toRotationMatrix();
    EXPECT_NEAR(
        (document.hose("right-return")->points().back() - (centre + rotation * (rightEnd - centre)))
            .norm(),
        0.0, 1e-9);
    EXPECT_NEAR(
        (document.hose("left-feed")->point(16) - (centre + rotation * (leftEnd - centre))).norm(),
        0.0, 1e-9);
    EXPECT_GT((document.hose("left-feed")->point(16) - leftEnd).norm(), 0.02);
    EXPECT_GT((document.hose("left-feed")->point(8) - leftMiddle).norm(), 1e-4)
        << "the hose followed live, not only its fixed points";

    // Saved as a pose override and restored on open.
    ASSERT_TRUE(m_window->save()) << m_errors.join('\n').toStdString();
    const auto turned = allPoints(document);
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    ASSERT_EQ(document.project().poses.size(), 1u);
    EXPECT_EQ(document.project().poses[0].node, "/test-rig/valve");
    EXPECT_TRUE(document.nodeWorldFrame("rig", valve).rotation.isApprox(after.rotation, 1e-12));
    EXPECT_NEAR((document.hose("right-return")->points().back() - turned[1].back()).norm(), 0.0,
                1e-9);

    // The export (exportProject, the CLI's code) writes the turned valve and the hoses built
    // at the saved pose: the same axis points as the reopened project's hoses.
    if (exportAvailable()) {
        const fs::path output = outputDir() / "rotate" / "turned.glb";
        fs::remove(output);
        m_window->action("actionExport")->trigger();
        m_window->exportDialog().setOutputPath(QString::fromStdString(output.string()));
        ASSERT_TRUE(m_window->exportDialog().runExport())
            << m_window->exportDialog().summaryText().toStdString();
        m_window->exportDialog().hide();
        const QJsonObject gltf = readGlb(output);
        const Eigen::Quaterniond posedLocal(
            Eigen::Matrix3d(document.nodeLocalTransform("rig", valve).topLeftCorner<3, 3>()));
        int valves = 0;
        for (const auto& node : gltf["nodes"].toArray()) {
            const QJsonObject object = node.toObject();
            if (object["name"].toString() != "valve") continue;
            ++valves;
            const QJsonArray q = object["rotation"].toArray();
            ASSERT_EQ(q.size(), 4);
            const Eigen::Quaterniond written(q[3].toDouble(), q[0].toDouble(), q[1].toDouble(),
                                             q[2].toDouble());
            EXPECT_GT(std::abs(written.dot(posedLocal)), 1.0 - 1e-6) << "the valve is turned";
        }
        EXPECT_EQ(valves, 1);
        const QJsonArray hoses =
            gltf["extensions"].toObject()["CHAINTUBE_hose_rig"].toObject()["hoses"].toArray();
        ASSERT_EQ(hoses.size(), 2);
        for (const auto& entry : hoses) {
            const QJsonObject hose = entry.toObject();
            const Hose* live = document.hose(hose["id"].toString().toStdString());
            ASSERT_TRUE(live);
            const QJsonArray axis = hose["axis"].toArray();
            ASSERT_EQ(axis.size(), live->pointCount());
            for (int p = 0; p < live->pointCount(); ++p) {
                const QJsonArray point = axis[p].toArray();
                EXPECT_NEAR((Vec3(point[0].toDouble(), point[1].toDouble(), point[2].toDouble()) -
                             live->point(p))
                                .norm(),
                            0.0, 1e-9)
                    << hose["id"].toString().toStdString() << " point " << p;
            }
        }
    }

    // Undo after the reopen has nothing to undo; reset through the undo of a fresh edit.
    EXPECT_FALSE(document.undoStack()->canUndo());
    document.undoStack()->push(makeSetNodeTransform(document, {"rig", valve}, std::nullopt));
    settle();
    EXPECT_EQ(initialPoints, allPoints(document)) << "back at the file pose: the built shape";
    EXPECT_TRUE(document.project().poses.empty());
}

} // namespace
} // namespace chaintube::editor
