// End-to-end tests of the real main window under xvfb-run (platform xcb, Mesa), driven with
// QTest mouse and key events: open a sample, grab-drag a hose, lay out a new hose by clicks on
// the scene, fix one end to a part, move the part (gizmo and numeric field), check the hose
// followed, undo everything, export and validate the written file. Also: the unsaved-changes
// prompt, autosave recovery, refusing invalid values, one undo step per slider drag, the
// problems panel. Screenshots go to the test output folder (CHAINTUBE_UPDATE_SCREENSHOTS=1:
// to editor/screenshots).
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
#include "test_support.h"
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

/// A main window on screen with prompts answered by the test.
QString writeProject(const std::string& folderName, const QJsonObject& scene);

/// The L-bracket the route tests on the STEP assembly click on.
const std::string kStepBracket = "/as1/l-bracket-assembly_1/l-bracket_1";

class MainWindowTest : public ::testing::Test
{
protected:
    void SetUp() override { m_window = makeWindow(); }
    std::unique_ptr<MainWindow> makeWindow()
    {
        auto window = std::make_unique<MainWindow>(test::roots());
        window->ask = [this](const QString& title, const QString&, QMessageBox::StandardButtons) {
            m_questions << title;
            return m_answer;
        };
        window->showError = [this](const QString& title, const QString& text) {
            m_errors << title + ": " + text;
        };
        window->resize(1280, 800);
        window->show();
        EXPECT_TRUE(QTest::qWaitForWindowExposed(window.get()));
        window->activateWindow();
        QApplication::setActiveWindow(window.get());
        return window;
    }
    void settle()
    {
        takeKeys();
        m_window->viewport().repaint();
        QApplication::processEvents();
    }
    /// Under xvfb no window manager gives the window the focus back when a dialog it opened
    /// closes (the import's progress dialog, shown once an import takes 300 ms, so only on a
    /// loaded machine): with no window active, its window-wide shortcuts (Return finishing a
    /// route, Ctrl+Z) would go nowhere. The window asks for the focus and waits until it has it.
    void takeKeys()
    {
        QApplication::processEvents();
        if (!m_window || QApplication::activeWindow()) return;
        m_window->activateWindow();
        EXPECT_TRUE(QTest::qWaitForWindowActive(m_window.get()));
    }
    /// Selects a hose of the open document (the properties panel then shows it).
    void selectHose(const std::string& id)
    {
        Selection selection;
        selection.hoseId = id;
        m_window->document().setSelection(selection);
        settle();
    }
    /// A copy of the test rig in a fresh folder (so that saving never touches samples/).
    QString copyOfTestRig(const std::string& folderName)
    {
        const fs::path folder = test::outputDir() / folderName;
        fs::remove_all(folder);
        fs::create_directories(folder / "scenes");
        fs::copy_file(test::samplesDir() / "test-rig.ctproj", folder / "test-rig.ctproj");
        fs::copy_file(test::samplesDir() / "scenes/test-rig.gltf", folder / "scenes/test-rig.gltf");
        return QString::fromStdString((folder / "test-rig.ctproj").string());
    }
    void screenshot(const char* name)
    {
        // What a person sees a moment later: the problems panel recomputes at most every
        // 100 ms after a change, so without this the picture could show an earlier state's list.
        m_window->problems().refreshNow();
        settle();
        const QImage image = m_window->grab().toImage();
        const QString file = QString::fromStdString((test::outputDir() / name).string());
        EXPECT_TRUE(image.save(file));
        if (std::getenv("CHAINTUBE_UPDATE_SCREENSHOTS"))
            image.save(QString(CHAINTUBE_SCREENSHOT_DIR) + "/" + name);
    }
    /// Screen positions (8 px grid) whose pick hits node `path` from above (normal up).
    std::vector<std::pair<QPoint, ScenePickHit>> topHits(const std::string& path)
    {
        std::vector<std::pair<QPoint, ScenePickHit>> hits;
        Viewport& viewport = m_window->viewport();
        for (int y = 4; y < viewport.height(); y += 8)
            for (int x = 4; x < viewport.width(); x += 8) {
                ScenePickHit hit;
                if (viewport.pickScene(QPointF(x, y), &hit) && hit.normal.y() > 0.9 &&
                    m_window->document().scene(hit.sceneId)->nodes[size_t(hit.node)].path == path)
                    hits.push_back({QPoint(x, y), hit});
            }
        return hits;
    }
    /// Opens the STEP bracket assembly (as1-oc-214.stp of the scenes folder) as the one scene of
    /// a new project in `folderName`, frames it (Home) and starts a new hose (N); `bracket`
    /// receives the collider of kStepBracket at its pose. Skips the test where the scene is
    /// absent: check IsSkipped() and HasFatalFailure() after the call.
    void openStepBracketToLayARoute(const std::string& folderName,
                                    std::shared_ptr<MeshCollider>* bracket)
    {
        if (!fs::exists(test::scenesDir() / "as1-oc-214.stp"))
            GTEST_SKIP() << "CHAINTUBE_SCENES_DIR has no as1-oc-214.stp: STEP bracket test skipped";
        const QJsonObject scene{
            {"id", "as1"},
            {"path", "scenes:as1-oc-214.stp"},
            {"import", QJsonObject{{"chordalTolerance", 1e-4}, {"angularTolerance", 0.5}}}};
        ASSERT_TRUE(m_window->openFile(writeProject(folderName, scene)))
            << m_errors.join('\n').toStdString();
        // The import's progress dialog had the focus: the window takes the keys again.
        m_window->activateWindow();
        QApplication::setActiveWindow(m_window.get());
        QTest::keyClick(&m_window->viewport(), Qt::Key_Home);
        settle();
        QTest::keyClick(&m_window->viewport(), Qt::Key_N);
        ASSERT_EQ(m_window->viewport().mode(), Viewport::Mode::LayRoute);
        const Document& document = m_window->document();
        const formats::ImportedScene& as1 = *document.scene("as1");
        const int node = as1.findNode(kStepBracket);
        ASSERT_GE(node, 0);
        *bracket = formats::nodeCollider(as1, node, document.nodeWorldTransform("as1", node));
        ASSERT_TRUE(*bracket);
    }
    void clickTreeItem(const QString& text)
    {
        QTreeWidget& tree = m_window->sceneTree();
        const auto items = tree.findItems(text, Qt::MatchExactly | Qt::MatchRecursive);
        ASSERT_FALSE(items.isEmpty()) << text.toStdString();
        tree.scrollToItem(items.first());
        const QRect rect = tree.visualItemRect(items.first());
        QTest::mouseClick(tree.viewport(), Qt::LeftButton, {}, rect.center());
    }
    void drag(QWidget* widget, QPoint from, QPoint to, int steps = 8)
    {
        QTest::mousePress(widget, Qt::LeftButton, {}, from);
        for (int i = 1; i <= steps; ++i)
            QTest::mouseMove(widget, from + (to - from) * i / steps);
        QTest::mouseRelease(widget, Qt::LeftButton, {}, to);
        settle();
    }

    /// Lays out a new hose by clicks on the floor plate nearest (in x and z) each of `spots`
    /// (N, the clicks, Enter); returns the route points as the clicks placed them.
    std::vector<Vec3> layRouteOnTheFloor(const std::vector<Vec3>& spots)
    {
        Viewport& viewport = m_window->viewport();
        const auto floor = topHits("/test-rig/floor_plate");
        EXPECT_FALSE(floor.empty());
        if (floor.empty()) return {};
        QTest::keyClick(&viewport, Qt::Key_N);
        for (const Vec3& spot : spots) {
            auto d = [&](const Vec3& p) { return std::hypot(p.x() - spot.x(), p.z() - spot.z()); };
            const auto nearest =
                std::min_element(floor.begin(), floor.end(), [&](const auto& a, const auto& b) {
                    return d(a.second.point) < d(b.second.point);
                });
            QTest::mouseClick(&viewport, Qt::LeftButton, {}, nearest->first);
        }
        const std::vector<Vec3> clicked = viewport.pendingRoute();
        EXPECT_EQ(clicked.size(), spots.size());
        takeKeys();
        QTest::keyClick(&viewport, Qt::Key_Return);
        settle();
        return clicked;
    }

    std::unique_ptr<MainWindow> m_window;
    QMessageBox::StandardButton m_answer = QMessageBox::No;
    QStringList m_questions;
    QStringList m_errors;
};

/// Calls `drive` every 30 ms while alive (modal dialogs run their own event loops, which
/// process the timer): the way these tests press buttons in real dialogs.
class DialogDriver
{
public:
    explicit DialogDriver(std::function<void()> drive)
    {
        QObject::connect(&m_timer, &QTimer::timeout, std::move(drive));
        m_timer.start(30);
    }

private:
    QTimer m_timer;
};

std::vector<std::vector<Vec3>> allPoints(const Document& document)
{
    std::vector<std::vector<Vec3>> points;
    for (const auto& hose : document.project().hoses)
        points.push_back(document.hose(hose.id) ? document.hose(hose.id)->points()
                                                : std::vector<Vec3>{});
    return points;
}

/// Checks a GLB's container and JSON; returns the JSON.
QJsonObject readGlb(const fs::path& file)
{
    QFile in(QString::fromStdString(file.string()));
    EXPECT_TRUE(in.open(QIODevice::ReadOnly)) << file;
    const QByteArray bytes = in.readAll();
    EXPECT_GE(bytes.size(), 20);
    if (bytes.size() < 20) return {};
    auto u32 = [&](int offset) {
        return quint32(quint8(bytes[offset])) | quint32(quint8(bytes[offset + 1])) << 8 |
               quint32(quint8(bytes[offset + 2])) << 16 | quint32(quint8(bytes[offset + 3])) << 24;
    };
    EXPECT_EQ(bytes.left(4), QByteArray("glTF"));
    EXPECT_EQ(u32(4), 2u);
    EXPECT_EQ(u32(8), quint32(bytes.size()));
    const quint32 jsonLength = u32(12);
    EXPECT_EQ(u32(16), 0x4E4F534Au); // "JSON"
    QJsonParseError error;
    const QJsonDocument json = QJsonDocument::fromJson(bytes.mid(20, int(jsonLength)), &error);
    EXPECT_EQ(error.error, QJsonParseError::NoError) << error.errorString().toStdString();
    return json.object();
}

TEST_F(MainWindowTest, LayOutFixMoveUndoAndExportOnTheTestRig)
{
    const QString project = copyOfTestRig("e2e");
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
    const fs::path output = test::outputDir() / "e2e" / "rig.glb";
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
    if (!test::haveScenes())
        GTEST_SKIP() << "CHAINTUBE_SCENES_DIR has no 2CylinderEngine.glb: engine test skipped";
    ASSERT_TRUE(
        m_window->openFile(QString::fromStdString((test::samplesDir() / "engine.ctproj").string())))
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

/// A project in a fresh output folder with the test rig's material presets, no hose and the
/// one scene `scene` (a "scenes" entry; a relative "path" names a copy of the test rig's
/// scene file). Returns the project file.
QString writeProject(const std::string& folderName, const QJsonObject& scene)
{
    const fs::path folder = test::outputDir() / folderName;
    fs::remove_all(folder);
    fs::create_directories(folder / "scenes");
    fs::copy_file(test::samplesDir() / "scenes/test-rig.gltf", folder / "scenes/test-rig.gltf");
    QFile rig(QString::fromStdString((test::samplesDir() / "test-rig.ctproj").string()));
    EXPECT_TRUE(rig.open(QIODevice::ReadOnly));
    QJsonObject project = QJsonDocument::fromJson(rig.readAll()).object();
    project["name"] = QString::fromStdString(folderName);
    project["scenes"] = QJsonArray{scene};
    project["hoses"] = QJsonArray();
    project.remove("poses");
    project.remove("sockets"); // on the rig's parts, which this project does not have
    const QString file = QString::fromStdString((folder / "project.ctproj").string());
    QFile out(file);
    EXPECT_TRUE(out.open(QIODevice::WriteOnly));
    out.write(QJsonDocument(project).toJson());
    return file;
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
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("route-valid-when-laid")));
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
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("route-tight-corner")));
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
    const QString project = copyOfTestRig("rotate");
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
        const fs::path output = test::outputDir() / "rotate" / "turned.glb";
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

TEST_F(MainWindowTest, AnUnknownNamedRootIsAskedForInADialogAndRemembered)
{
    // The test rig's project, its scene path naming a root "rigparts" nobody has defined.
    const fs::path folder = test::outputDir() / "named-root";
    fs::remove_all(folder);
    fs::create_directories(folder / "project");
    fs::create_directories(folder / "parts");
    fs::copy_file(test::samplesDir() / "scenes/test-rig.gltf", folder / "parts/test-rig.gltf");
    formats::Project rig = formats::loadProject(test::samplesDir() / "test-rig.ctproj");
    rig.scenes[0].path = "rigparts:test-rig.gltf";
    const fs::path file = folder / "project/rig.ctproj";
    formats::saveProject(rig, file);
    QSettings().remove("roots/rigparts");
    const QString parts = QString::fromStdString((folder / "parts").string());

    // The wrong folder first (the project's own): asked again; then the right one.
    std::vector<QString> titles;
    auto driver = std::make_unique<DialogDriver>([&] {
        auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
        // (A property, not the address: the next dialog may reuse the same stack address.)
        if (!dialog || dialog->objectName() != "rootFolderDialog" || !dialog->isVisible() ||
            dialog->property("driven").toBool())
            return;
        dialog->setProperty("driven", true);
        titles.push_back(dialog->windowTitle());
        auto* name = dialog->findChild<QLineEdit*>("fileNameEdit");
        ASSERT_TRUE(name);
        name->setText(titles.size() == 1 ? QString::fromStdString((folder / "project").string())
                                         : parts);
        QTest::keyClick(name, Qt::Key_Return);
    });
    ASSERT_TRUE(m_window->openFile(QString::fromStdString(file.string())))
        << m_errors.join('\n').toStdString();
    ASSERT_EQ(titles.size(), 2u) << "a folder without the scene is not accepted";
    EXPECT_TRUE(titles[0].contains("rigparts")) << titles[0].toStdString();
    EXPECT_TRUE(titles[0].contains("rigparts:test-rig.gltf")) << titles[0].toStdString();
    ASSERT_TRUE(m_window->document().scene("rig")) << "opened with the chosen folder";
    EXPECT_EQ(m_window->document().hoseCount(), 2);
    EXPECT_TRUE(m_errors.isEmpty()) << m_errors.join('\n').toStdString();

    // Remembered in the settings: the next start knows the root without asking.
    EXPECT_EQ(QSettings().value("roots/rigparts").toString(), parts);
    QString error;
    const formats::NamedRoots remembered = editorRoots({}, &error);
    ASSERT_TRUE(remembered.count("rigparts"));
    EXPECT_EQ(remembered.at("rigparts"), fs::path(parts.toStdString()));
    m_window.reset();
    auto restarted = std::make_unique<MainWindow>(remembered);
    restarted->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(restarted.get()));
    ASSERT_TRUE(restarted->openFile(QString::fromStdString(file.string())));
    EXPECT_EQ(titles.size(), 2u) << "not asked again";
    EXPECT_TRUE(restarted->document().scene("rig"));
    restarted.reset();
    m_window = makeWindow();

    // Cancelling the question: the project opens with the scene marked missing, naming the
    // root (Locate… can find it later).
    driver.reset();
    QSettings().remove("roots/rigparts");
    m_window.reset();
    m_window = makeWindow();
    DialogDriver canceller([&] {
        auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
        if (dialog && dialog->objectName() == "rootFolderDialog" && dialog->isVisible())
            dialog->reject();
    });
    m_errors.clear();
    EXPECT_TRUE(m_window->openFile(QString::fromStdString(file.string())));
    EXPECT_TRUE(m_errors.isEmpty()) << m_errors.join('\n').toStdString();
    ASSERT_EQ(m_window->document().missingScenes().count("rig"), 1u);
    EXPECT_NE(m_window->document().missingScenes().at("rig").find("rigparts"), std::string::npos)
        << m_window->document().missingScenes().at("rig");
    EXPECT_FALSE(m_window->document().scene("rig"));
    QSettings().remove("roots/rigparts");
}

/// Writes an OBJ grid of n × n quads (2 n² triangles): big enough that importing it takes a
/// while (the progress dialog appears after 300 ms).
fs::path writeGridObj(const fs::path& file, int n)
{
    std::ofstream out(file);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            out << "v " << i * 0.001 << " " << 0.0001 * ((i * 7 + j * 13) % 5) << " " << j * 0.001
                << "\n";
    out << "o grid\n";
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
            out << "f " << a << " " << c << " " << b << "\nf " << b << " " << c << " " << d << "\n";
        }
    return file;
}

/// When the Import dialog shows: `choose(dialog)` picks the author's settings, then Import is
/// pressed with the mouse. Returns true if it did.
bool pressImport(const std::function<void(QDialog&)>& choose)
{
    for (QWidget* widget : QApplication::topLevelWidgets()) {
        auto* dialog = qobject_cast<QDialog*>(widget);
        if (!dialog || dialog->objectName() != "importDialog" || !dialog->isVisible()) continue;
        if (choose) choose(*dialog);
        auto* buttons = dialog->findChild<QDialogButtonBox*>("importButtons");
        QTest::mouseClick(buttons->button(QDialogButtonBox::Ok), Qt::LeftButton);
        return true;
    }
    return false;
}

/// An OBJ of one box, `size` file units wide, its low corner at `low` (file units).
fs::path writeBoxObj(const fs::path& file, const Vec3& low, double size)
{
    std::ofstream out(file);
    for (int corner = 0; corner < 8; ++corner)
        out << "v " << low.x() + ((corner & 1) ? size : 0) << " "
            << low.y() + ((corner & 2) ? size : 0) << " " << low.z() + ((corner & 4) ? size : 0)
            << "\n";
    out << "o box\n";
    for (const char* face : {"1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6"})
        out << "f " << face << "\n";
    return file;
}

// The Import dialog says which units and up axis the reader assumed and where each came
// from, lets the author change them, and places the scene at the origin (an empty project) or
// beside what is there.
TEST_F(MainWindowTest, ImportShowsTheAssumedUnitsAndPlacesTheScene)
{
    const fs::path folder = test::outputDir() / "import-dialog";
    fs::create_directories(folder);
    // A 400 mm box drawn in millimetres far from the origin; OBJ does not say its unit.
    const fs::path box = writeBoxObj(folder / "box.obj", Vec3(5000, 2000, -3000), 400);
    Document& document = m_window->document();
    QString assumed;
    QString size;
    {
        DialogDriver drive([&] {
            pressImport([&](QDialog& dialog) {
                assumed = dialog.findChild<QLabel*>("importAssumed")->text();
                auto* unit = dialog.findChild<QComboBox*>("importUnit");
                unit->setCurrentIndex(unit->findText("millimetre"));
                size = dialog.findChild<QLabel*>("importSize")->text();
                EXPECT_TRUE(dialog.findChild<QRadioButton*>("placeAtOrigin")->isChecked())
                    << "an empty project: at the origin";
            });
        });
        ASSERT_TRUE(m_window->importSceneFile(QString::fromStdString(box.string())))
            << m_errors.join('\n').toStdString();
    } // the first import's dialog driver stops here
    EXPECT_TRUE(assumed.contains("metre")) << assumed.toStdString();
    EXPECT_TRUE(assumed.contains("assumed")) << assumed.toStdString();
    EXPECT_TRUE(size.startsWith("0.4 × 0.4 × 0.4 m")) << size.toStdString();
    ASSERT_EQ(document.project().scenes.size(), 1u);
    const formats::SceneReference& first = document.project().scenes[0];
    EXPECT_EQ(first.import.metresPerUnit, 0.001) << "kept in the project";
    const auto [low, high] = sceneBounds(*document.scene(first.id));
    EXPECT_NEAR(high.x() - low.x(), 0.4, 1e-6);
    EXPECT_NEAR(0.5 * (low.x() + high.x()), 0.0, 1e-6) << "centred on the origin";
    EXPECT_NEAR(0.5 * (low.z() + high.z()), 0.0, 1e-6);
    EXPECT_NEAR(low.y(), 0.0, 1e-6) << "standing on the floor";

    // The same file again: beside the first one, on the same floor.
    DialogDriver again([&] {
        pressImport([](QDialog& dialog) {
            auto* unit = dialog.findChild<QComboBox*>("importUnit");
            unit->setCurrentIndex(unit->findText("millimetre"));
            EXPECT_TRUE(dialog.findChild<QRadioButton*>("placeBeside")->isChecked());
        });
    });
    ASSERT_TRUE(m_window->importSceneFile(QString::fromStdString(box.string())));
    ASSERT_EQ(document.project().scenes.size(), 2u);
    const auto [low2, high2] = sceneBounds(*document.scene(document.project().scenes[1].id));
    EXPECT_GT(low2.x(), high.x()) << "to the right of the first";
    EXPECT_NEAR(low2.y(), 0.0, 1e-6);
    EXPECT_EQ(document.undoStack()->count(), 2) << "one undo step per import";
    // Saved and reopened, both are where they were placed.
    const QString project = QString::fromStdString((folder / "placed.ctproj").string());
    ASSERT_TRUE(m_window->saveAs(project)) << m_errors.join('\n').toStdString();
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    const auto [low3, high3] = sceneBounds(*document.scene(document.project().scenes[1].id));
    EXPECT_NEAR((low3 - low2).norm(), 0.0, 1e-9);
}

TEST_F(MainWindowTest, SceneImportShowsProgressAndCancelStopsIt)
{
    const fs::path folder = test::outputDir() / "import-progress";
    fs::create_directories(folder);
    // Large enough that the dialog shows (QProgressDialog pops up after 300 ms only when the
    // estimated rest is at least as long) on a fast machine too: 450 × 450 imported in ~0.5 s
    // on the EPYC VM and the dialog sometimes never showed. Cancelled early, so its size costs
    // little.
    const fs::path grid = writeGridObj(folder / "grid.obj", 900);
    Document& document = m_window->document();
    ASSERT_TRUE(document.scenes().empty());

    // 1. Cancel: pressed with the mouse once the dialog shows.
    QString label;
    int dialogs = 0;
    bool pressed = false;
    DialogDriver cancel([&] {
        for (QWidget* widget : QApplication::topLevelWidgets()) {
            auto* progress = qobject_cast<QProgressDialog*>(widget);
            if (!progress || progress->objectName() != "progressDialog" || !progress->isVisible() ||
                pressed)
                continue;
            ++dialogs;
            label = progress->labelText();
            QPushButton* button = progress->findChild<QPushButton*>();
            ASSERT_TRUE(button);
            EXPECT_EQ(button->text(), "Cancel");
            QTest::mouseClick(button, Qt::LeftButton);
            pressed = true;
        }
    });
    EXPECT_FALSE(m_window->importSceneFile(QString::fromStdString(grid.string())));
    EXPECT_EQ(dialogs, 1) << "the progress dialog showed";
    EXPECT_TRUE(label.contains("grid.obj")) << label.toStdString();
    EXPECT_TRUE(document.scenes().empty()) << "a cancelled import adds nothing";
    EXPECT_EQ(document.undoStack()->count(), 0);
    EXPECT_TRUE(m_errors.isEmpty()) << "cancelling is not an error";
    EXPECT_EQ(m_window->statusBar()->currentMessage(), "Import cancelled");
}

TEST_F(MainWindowTest, SceneImportProgressAdvancesToTheEnd)
{
    const fs::path folder = test::outputDir() / "import-progress";
    fs::create_directories(folder);
    // ~2x the work of the 450 × 450 grid this test used until it imported fast enough on the
    // EPYC VM that the dialog could stay hidden (see SceneImportShowsProgressAndCancelStopsIt).
    const int n = 640;
    const fs::path grid = writeGridObj(folder / "grid-whole.obj", n);
    std::vector<int> values;
    DialogDriver watch([&] {
        for (QWidget* widget : QApplication::topLevelWidgets())
            if (auto* progress = qobject_cast<QProgressDialog*>(widget))
                if (progress->objectName() == "progressDialog" && progress->isVisible())
                    values.push_back(progress->value());
        pressImport({});
    });
    ASSERT_TRUE(m_window->importSceneFile(QString::fromStdString(grid.string())))
        << m_errors.join('\n').toStdString();
    ASSERT_FALSE(values.empty()) << "the progress dialog showed";
    EXPECT_TRUE(std::is_sorted(values.begin(), values.end())) << "progress never goes back";
    Document& document = m_window->document();
    ASSERT_EQ(document.scenes().size(), 1u);
    EXPECT_EQ(document.scenes().begin()->second.instancedTriangleCount(), 2u * n * n);
    EXPECT_EQ(document.undoStack()->count(), 1) << "an import is one undo step";
    // The tree lists the imported node.
    EXPECT_FALSE(
        m_window->sceneTree().findItems("grid", Qt::MatchExactly | Qt::MatchRecursive).isEmpty());
}

TEST_F(MainWindowTest, RecentFilesAreListedNewestFirstAndOpenFromTheMenu)
{
    QSettings().remove("recentFiles");
    m_window.reset();
    m_window = makeWindow();
    const QString first = copyOfTestRig("recent-a");
    const QString second = copyOfTestRig("recent-b");
    ASSERT_TRUE(m_window->openFile(first));
    ASSERT_TRUE(m_window->openFile(second));
    auto* menu = m_window->findChild<QMenu*>("recentMenu");
    ASSERT_TRUE(menu);
    auto tips = [](QMenu* m) {
        QStringList list;
        for (QAction* action : m->actions())
            list << action->toolTip();
        return list;
    };
    EXPECT_EQ(tips(menu), (QStringList{second, first})) << "newest first";

    // A restart shows the same list; clicking the older entry opens it and moves it up.
    m_window.reset();
    m_window = makeWindow();
    menu = m_window->findChild<QMenu*>("recentMenu");
    ASSERT_TRUE(menu);
    ASSERT_EQ(tips(menu), (QStringList{second, first}));
    menu->popup(m_window->mapToGlobal(QPoint(40, 40)));
    ASSERT_TRUE(QTest::qWaitForWindowExposed(menu));
    QAction* older = menu->actions().at(1);
    QTest::mouseClick(menu, Qt::LeftButton, {}, menu->actionGeometry(older).center());
    // The click reaches the menu through the window system: on a loaded machine a few event
    // rounds later (at most 250 of them).
    const auto openName = [&] {
        return QString::fromStdString(m_window->document().fileName().string());
    };
    for (int round = 0; round < 250 && openName() != first; ++round)
        QTest::qWait(20);
    settle();
    EXPECT_EQ(openName(), first);
    EXPECT_EQ(tips(menu), (QStringList{first, second}));

    // At most 8 entries.
    for (int i = 0; i < 9; ++i)
        ASSERT_TRUE(m_window->openFile(copyOfTestRig("recent-" + std::to_string(i))));
    EXPECT_EQ(menu->actions().size(), 8);
    QSettings().remove("recentFiles");
}

TEST_F(MainWindowTest, TheUnsavedChangesPromptIsARealDialogThatCanCancelOrDiscard)
{
    // A window with its own question box (not the fixture's answering function).
    m_window.reset();
    auto window = std::make_unique<MainWindow>(test::roots());
    window->resize(1280, 800);
    window->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(window.get()));
    ASSERT_TRUE(window->openFile(copyOfTestRig("prompt")));
    Document& document = window->document();
    Selection selection;
    selection.hoseId = "left-feed";
    document.setSelection(selection);
    window->findChild<QDoubleSpinBox*>("diameter")->setValue(31.0);
    ASSERT_TRUE(document.isModified());
    const std::string edited = document.stateFingerprint();

    QMessageBox::StandardButton press = QMessageBox::Cancel;
    QStringList texts;
    DialogDriver driver([&] {
        auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
        if (!box || !box->isVisible() || box->property("driven").toBool()) return;
        box->setProperty("driven", true);
        texts << box->text();
        ASSERT_TRUE(box->button(press));
        QTest::mouseClick(box->button(press), Qt::LeftButton);
    });
    // New → Cancel: nothing lost.
    window->action("actionNew")->trigger();
    ASSERT_EQ(texts.size(), 1);
    EXPECT_TRUE(texts[0].contains("unsaved changes")) << texts[0].toStdString();
    EXPECT_EQ(document.stateFingerprint(), edited);
    // Closing the window → Cancel: the window stays.
    window->close();
    EXPECT_EQ(texts.size(), 2);
    EXPECT_TRUE(window->isVisible());
    EXPECT_EQ(document.stateFingerprint(), edited);
    // New → Discard: an untitled project.
    press = QMessageBox::Discard;
    window->action("actionNew")->trigger();
    EXPECT_EQ(texts.size(), 3);
    EXPECT_TRUE(window->document().fileName().empty());
    EXPECT_EQ(window->document().hoseCount(), 0);
    EXPECT_FALSE(window->document().isModified());
    window.reset();
    m_window = makeWindow();
}

TEST_F(MainWindowTest, TheWindowLayoutIsRememberedAcrossRestarts)
{
    // A layout unlike the default: problems docked left, history hidden, wireframe on, a
    // smaller window.
    auto* problems = m_window->findChild<QDockWidget*>("problemsDock");
    auto* history = m_window->findChild<QDockWidget*>("historyDock");
    ASSERT_TRUE(problems && history);
    ASSERT_NE(m_window->dockWidgetArea(problems), Qt::LeftDockWidgetArea);
    m_window->addDockWidget(Qt::LeftDockWidgetArea, problems);
    history->hide();
    m_window->action("actionWireframe")->setChecked(true);
    m_window->resize(1100, 700);
    settle();
    const QSize size = m_window->size();
    ASSERT_TRUE(m_window->close()) << "closing saves the layout";
    m_window.reset();

    // A restart (a new window; no resize by the test this time).
    auto restarted = std::make_unique<MainWindow>(test::roots());
    restarted->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(restarted.get()));
    auto* problemsAgain = restarted->findChild<QDockWidget*>("problemsDock");
    auto* historyAgain = restarted->findChild<QDockWidget*>("historyDock");
    EXPECT_EQ(restarted->dockWidgetArea(problemsAgain), Qt::LeftDockWidgetArea);
    EXPECT_FALSE(historyAgain->isVisible());
    EXPECT_TRUE(restarted->action("actionWireframe")->isChecked());
    EXPECT_TRUE(restarted->viewport().wireframe());
    EXPECT_EQ(restarted->size(), size);
    restarted.reset();
    // The other tests start from the default layout.
    QSettings settings;
    settings.remove("window");
    settings.remove("view");
    m_window = makeWindow();
}

TEST_F(MainWindowTest, UnsavedChangesPromptAndAutosaveRecovery)
{
    const QString project = copyOfTestRig("recovery");
    ASSERT_TRUE(m_window->openFile(project));
    Document& document = m_window->document();
    // An edit, then "New": the prompt appears; Cancel keeps everything.
    m_window->findChild<QDoubleSpinBox*>("diameter")->setValue(0); // refused below min: clamps
    Selection selection;
    selection.hoseId = "left-feed";
    document.setSelection(selection);
    m_window->findChild<QDoubleSpinBox*>("diameter")->setValue(33.0);
    ASSERT_TRUE(document.isModified());
    const std::string edited = document.stateFingerprint();
    m_answer = QMessageBox::Cancel;
    m_window->action("actionNew")->trigger();
    EXPECT_EQ(m_questions.size(), 1);
    EXPECT_EQ(edited, document.stateFingerprint()) << "Cancel kept the project";
    // Autosave, then "crash": the window goes away without closing.
    const QString autosave = m_window->autosaveNow();
    ASSERT_FALSE(autosave.isEmpty());
    ASSERT_TRUE(QFile::exists(autosave));
    m_window.reset();
    // A new main window (the editor started again) opens the project and is offered the
    // autosave.
    m_window = makeWindow();
    m_answer = QMessageBox::Yes;
    m_questions.clear();
    ASSERT_TRUE(m_window->openFile(project));
    ASSERT_EQ(m_questions.size(), 1) << "recovery was offered";
    EXPECT_EQ(edited, m_window->document().stateFingerprint());
    EXPECT_TRUE(m_window->document().isModified());
    EXPECT_TRUE(m_window->windowTitle().contains("test-rig.ctproj"));
    // Saving writes the recovered state and removes the autosave.
    ASSERT_TRUE(m_window->save());
    EXPECT_FALSE(QFile::exists(autosave));
    EXPECT_FALSE(m_window->document().isModified());
}

TEST_F(MainWindowTest, PropertiesRefuseInvalidValuesAndASliderDragIsOneStep)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("properties")));
    Document& document = m_window->document();
    selectHose("left-feed");
    // A slider drag: many values, one undo step, applied live.
    auto* slider = m_window->findChild<QSlider*>("diameterSlider");
    slider->setSliderDown(true);
    for (int mm = 21; mm <= 30; ++mm) {
        slider->setValue(mm);
        EXPECT_NEAR(document.hoseDefinition("left-feed")->outerDiameter, mm / 1000.0, 1e-12);
        EXPECT_NEAR(document.hose("left-feed")->outerRadius(), mm / 2000.0, 1e-12) << "live";
    }
    slider->setSliderDown(false);
    EXPECT_EQ(document.undoStack()->count(), 1);
    // Rounded rectangle with a corner radius larger than half the height: refused.
    const std::string before = document.stateFingerprint();
    auto* corner = m_window->findChild<QDoubleSpinBox*>("cornerRadius");
    auto* shape = m_window->findChild<QComboBox*>("shape");
    m_window->findChild<QDoubleSpinBox*>("profileHeight")->setValue(10.0);
    const int steps = document.undoStack()->count();
    corner->setValue(9.0); // still a circle: accepted, no effect on the shape
    shape->setCurrentIndex(3);
    emit shape->activated(3);
    EXPECT_FALSE(m_window->properties().lastRefusal().isEmpty())
        << "corner radius 9 mm > height/2 must be refused";
    EXPECT_EQ(document.hoseDefinition("left-feed")->profile.shape, Profile::Shape::Circle);
    EXPECT_EQ(shape->currentIndex(), 0) << "the widget shows the document's value again";
    EXPECT_LE(document.undoStack()->count(), steps + 2);
    (void)before;
}

// With no hose selected the hose fields are blank (not the spin boxes' minimum, not the last
// hose's values); selecting a hose again shows its values, a value at a field's minimum too.
TEST_F(MainWindowTest, HoseFieldsAreBlankWithNoHoseSelected)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("blank")));
    auto* diameter = m_window->findChild<QDoubleSpinBox*>("diameter");
    auto* segments = m_window->findChild<QSpinBox*>("segments");
    auto* name = m_window->findChild<QLineEdit*>("hoseName");
    auto* shape = m_window->findChild<QComboBox*>("shape");
    selectHose("left-feed");
    EXPECT_EQ(diameter->text(),
              QString("%1 mm").arg(m_window->document().hoseDefinition("left-feed")->outerDiameter *
                                       1000.0,
                                   0, 'f', 1));
    EXPECT_FALSE(name->text().isEmpty());
    selectHose("");
    EXPECT_FALSE(diameter->isEnabled());
    EXPECT_TRUE(diameter->text().trimmed().isEmpty()) << diameter->text().toStdString();
    EXPECT_TRUE(segments->text().trimmed().isEmpty()) << segments->text().toStdString();
    EXPECT_TRUE(name->text().isEmpty());
    EXPECT_TRUE(shape->currentText().isEmpty());
    // An inextensible hose (expansion 0 %, the field's minimum) shows "0.0 %", not the blank.
    selectHose("left-feed");
    auto* expansion = m_window->findChild<QDoubleSpinBox*>("expansion");
    expansion->setValue(expansion->minimum());
    settle();
    ASSERT_EQ(m_window->document().hose("left-feed")->spec().material.expansionCoefficient, 0.0);
    EXPECT_EQ(expansion->text(), "0.0 %");
    EXPECT_EQ(segments->text(),
              QString::number(m_window->document().hose("left-feed")->segmentCount()));
}

// The profile fields a shape is not made from cannot be edited: sides for circle and ellipse,
// width × height for ellipse and both rectangles, corner radius for the rounded rectangle.
TEST_F(MainWindowTest, ProfileFieldsFollowTheShape)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("profile-fields")));
    Document& document = m_window->document();
    selectHose("left-feed");
    auto* shape = m_window->findChild<QComboBox*>("shape");
    auto* sides = m_window->findChild<QSpinBox*>("sides");
    auto* width = m_window->findChild<QDoubleSpinBox*>("profileWidth");
    auto* height = m_window->findChild<QDoubleSpinBox*>("profileHeight");
    auto* corner = m_window->findChild<QDoubleSpinBox*>("cornerRadius");
    auto* segments = m_window->findChild<QSpinBox*>("cornerSegments");
    ASSERT_TRUE(shape && sides && width && height && corner && segments);
    ASSERT_EQ(shape->currentIndex(), 0);
    auto enabled = [&] {
        return std::vector<bool>{sides->isEnabled(), width->isEnabled(), height->isEnabled(),
                                 corner->isEnabled(), segments->isEnabled()};
    };
    EXPECT_EQ(enabled(), (std::vector<bool>{true, false, false, false, false})) << "circle";
    const Profile::Shape shapes[] = {Profile::Shape::Ellipse, Profile::Shape::Rectangle,
                                     Profile::Shape::RoundedRectangle};
    const std::vector<bool> expected[] = {{true, true, true, false, false},
                                          {false, true, true, false, false},
                                          {false, true, true, true, true}};
    for (int index = 1; index <= 3; ++index) {
        shape->setCurrentIndex(index);
        emit shape->activated(index);
        settle();
        ASSERT_EQ(document.hoseDefinition("left-feed")->profile.shape, shapes[index - 1]);
        EXPECT_EQ(enabled(), expected[index - 1]) << "shape " << index;
    }
    // A rounded rectangle's corner segments (the project format had them, the panel did not).
    const int segmentsBefore = document.hoseDefinition("left-feed")->profile.cornerSegments;
    segments->setValue(9);
    settle();
    EXPECT_EQ(document.hoseDefinition("left-feed")->profile.cornerSegments, 9);
    EXPECT_EQ(document.hoseDefinition("left-feed")->profile.shape,
              Profile::Shape::RoundedRectangle);
    screenshot("editor-rounded-rectangle.png"); // looked at, not compared
    document.undoStack()->undo();
    settle();
    EXPECT_EQ(document.hoseDefinition("left-feed")->profile.cornerSegments, segmentsBefore);
    EXPECT_EQ(segments->value(), segmentsBefore);
    document.undoStack()->undo();
    document.undoStack()->undo();
    document.undoStack()->undo();
    settle();
    EXPECT_EQ(document.hoseDefinition("left-feed")->profile.shape, Profile::Shape::Circle);
    EXPECT_EQ(enabled(), (std::vector<bool>{true, false, false, false, false}))
        << "circle again after undo";

    // A polygon profile (only the project file can give one) is shown as such with no field to
    // edit: the panel showed it as a circle, and changing its sides turned it into one.
    formats::HoseDefinition polygon = *document.hoseDefinition("left-feed");
    polygon.profile.shape = Profile::Shape::Polygon;
    polygon.profile.points = {Vec2(-0.008, -0.006), Vec2(0.008, -0.006), Vec2(0.0, 0.008)};
    document.undoStack()->push(makeSetHoseDefinition(document, "left-feed", polygon, MergeId::None,
                                                     QStringLiteral("Polygon")));
    settle();
    EXPECT_EQ(shape->currentIndex(), 4);
    EXPECT_TRUE(shape->currentText().contains("Polygon"));
    EXPECT_EQ(enabled(), (std::vector<bool>{false, false, false, false, false})) << "polygon";
    sides->setValue(sides->value() + 1); // as a program could: still no change of shape
    EXPECT_EQ(document.hoseDefinition("left-feed")->profile.shape, Profile::Shape::Polygon);
}

TEST_F(MainWindowTest, ProblemsPanelListsAnOverstretchAndSelectsItOnClick)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("problems")));
    Document& document = m_window->document();
    ProblemsPanel& problems = m_window->problems();
    problems.refreshNow();
    const size_t before = problems.problems().size();
    // Pull the valve far away: both hoses fixed to it overstretch.
    Selection selection;
    selection.sceneId = "rig";
    selection.node = document.scene("rig")->findNode("/test-rig/valve");
    document.setSelection(selection);
    auto* x = m_window->findChild<QDoubleSpinBox*>("partTranslationX");
    x->setValue(x->value() - 500.0);
    problems.refreshNow();
    EXPECT_NE(problems.problems().size(), before);
    int overstretch = -1;
    for (size_t i = 0; i < problems.problems().size(); ++i)
        if (problems.problems()[i].text.contains("overstretched") ||
            problems.problems()[i].text.contains("more hose"))
            overstretch = int(i);
    ASSERT_GE(overstretch, 0);
    const Problem problem = problems.problems()[size_t(overstretch)];
    QTest::mouseClick(problems.viewport(), Qt::LeftButton, {},
                      problems.visualItemRect(problems.item(overstretch)).center());
    EXPECT_EQ(document.selection().hoseId, problem.hoseId);
    EXPECT_EQ(document.selection().rangeFirst, problem.firstPoint);
    EXPECT_EQ(document.selection().rangeLast, problem.lastPoint);
    m_window->viewport().frameSelection();
    screenshot("editor-problems.png");
}

/// Clicks a check box where a person would (its indicator), after scrolling it into view.
void clickCheckBox(QCheckBox* box)
{
    for (QWidget* w = box->parentWidget(); w; w = w->parentWidget())
        if (auto* scroll = qobject_cast<QScrollArea*>(w)) {
            scroll->ensureWidgetVisible(box);
            break;
        }
    QApplication::processEvents();
    QTest::mouseClick(box, Qt::LeftButton, {}, QPoint(8, box->height() / 2));
}

TEST_F(MainWindowTest, GravityTorsionAndColliderControlsEditThroughTheUndoStack)
{
    // The test rig plus a hose fixed at one end (prepared through the document and saved, so
    // that the window starts from a clean undo stack like after opening any project).
    const QString project = copyOfTestRig("gravity");
    ASSERT_TRUE(m_window->openFile(project));
    Document& document = m_window->document();
    const std::string id = test::addCantilever(document);
    ASSERT_TRUE(m_window->save());
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    settle();
    Viewport& viewport = m_window->viewport();
    auto* gravity = m_window->findChild<QCheckBox*>("gravity");
    auto* torsion = m_window->findChild<QCheckBox*>("torsion");
    auto* twistLimit = m_window->findChild<QDoubleSpinBox*>("twistLimit");
    auto* collider = m_window->findChild<QCheckBox*>("collider");
    ASSERT_TRUE(gravity && torsion && twistLimit && collider);

    // Nothing selected: every hose group and the part group are greyed out.
    for (const char* group :
         {"hoseGroup", "materialGroup", "profileGroup", "physicsGroup", "fixGroup", "partGroup"}) {
        auto* box = m_window->findChild<QGroupBox*>(group);
        ASSERT_TRUE(box) << group;
        EXPECT_FALSE(box->isEnabled()) << group << " enabled with nothing selected";
    }

    // Select the hose by clicking it in the viewport; gravity on by clicking the check box.
    QTest::mouseClick(&viewport, Qt::LeftButton, {},
                      viewport.toWidget(document.hose(id)->point(12)));
    ASSERT_EQ(document.selection().hoseId, id);
    EXPECT_TRUE(m_window->findChild<QGroupBox*>("physicsGroup")->isEnabled());
    EXPECT_FALSE(m_window->findChild<QGroupBox*>("partGroup")->isEnabled());
    const std::vector<Vec3> authored = document.hose(id)->points();
    clickCheckBox(gravity);
    EXPECT_TRUE(gravity->isChecked());
    ASSERT_TRUE(document.hoseDefinition(id)->gravity.enabled);
    EXPECT_EQ(document.hoseDefinition(id)->gravity.direction, Vec3(0.0, -1.0, 0.0));
    EXPECT_EQ(document.undoStack()->count(), 1);
    EXPECT_TRUE(m_window->gravityTimerActive()) << "the hose sags live";
    // The timer stops by itself: when the hose settles, or at the latest after
    // Document::kGravityStepBudget steps.
    while (m_window->gravityTimerActive())
        QTest::qWait(20);
    settle();
    ASSERT_EQ(document.gravityState(id), Document::GravityState::Settled);
    const std::vector<Vec3> sagged = document.hose(id)->points();
    const double expected = test::lowestReachableY(*document.hose(id));
    const double drop = authored[1].y() - expected;
    EXPECT_NEAR(test::lowestY(sagged), expected, 0.02 * drop);
    EXPECT_LT(test::lowestY(sagged), test::lowestY(authored) - 0.1);
    EXPECT_EQ(document.undoStack()->count(), 1) << "the sag itself is no undo step";
    EXPECT_TRUE(m_window->findChild<QLabel*>("gravityState")->text().contains("settled"));
    // From the side, so that the sag shows against the authored route (the straight line).
    viewport.frameSelection();
    viewport.camera().yaw = 0.2;
    viewport.camera().pitch = -0.2;
    viewport.camera().distance *= 1.6;
    viewport.update();
    screenshot("editor-gravity.png");

    // Ctrl+Z: gravity off, the hose exactly as laid out, the document clean again.
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_FALSE(document.hoseDefinition(id)->gravity.enabled);
    EXPECT_FALSE(gravity->isChecked());
    EXPECT_EQ(document.hose(id)->points(), authored);
    EXPECT_FALSE(document.isModified());
    EXPECT_FALSE(m_window->gravityTimerActive());

    // Torsion on and a twist limit typed in degrees (the model holds radians).
    EXPECT_FALSE(twistLimit->isEnabled()) << "no limit to set while torsion is off";
    clickCheckBox(torsion);
    ASSERT_TRUE(document.hoseDefinition(id)->torsion.enabled);
    ASSERT_TRUE(twistLimit->isEnabled());
    QTest::mouseClick(twistLimit, Qt::LeftButton, {}, QPoint(10, twistLimit->height() / 2));
    QTest::keyClick(twistLimit, Qt::Key_A, Qt::ControlModifier);
    QTest::keyClicks(twistLimit, "12.5");
    QTest::keyClick(twistLimit, Qt::Key_Return);
    EXPECT_NEAR(document.hoseDefinition(id)->torsion.twistLimit,
                12.5 * 3.14159265358979323846 / 180.0, 1e-15);
    EXPECT_EQ(document.undoStack()->count(), 2);
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    EXPECT_NEAR(document.hoseDefinition(id)->torsion.twistLimit, 0.1, 1e-15);
    EXPECT_TRUE(document.hoseDefinition(id)->torsion.enabled);

    // A part as collider: choose the floor plate in the scene tree, tick "Collider".
    clickTreeItem("floor_plate");
    const int floor = document.scene("rig")->findNode("/test-rig/floor_plate");
    ASSERT_EQ(document.selection().node, floor);
    ASSERT_TRUE(collider->isEnabled());
    EXPECT_FALSE(collider->isChecked());
    clickCheckBox(collider);
    EXPECT_TRUE(document.isCollider("rig", floor));
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    EXPECT_FALSE(document.isCollider("rig", floor));
    EXPECT_FALSE(collider->isChecked());
    clickCheckBox(collider);
    ASSERT_TRUE(document.isCollider("rig", floor));

    // Gravity on again, save, reopen: the flags come back and the hose sags to the same shape.
    // The floor plate is now a collider of the live hose: its sag stays clear of the plate
    // (lowest surface point about 4.5 mm above it), so the shape is the one without it up to
    // the rounding of the collision steps.
    Selection selection;
    selection.hoseId = id;
    document.setSelection(selection);
    clickCheckBox(gravity);
    ASSERT_TRUE(document.hoseDefinition(id)->gravity.enabled);
    ASSERT_EQ(document.hoseColliders(id).size(), 1u);
    ASSERT_TRUE(m_window->save());
    const std::vector<Vec3> saggedWithFloor = document.hose(id)->points();
    ASSERT_EQ(saggedWithFloor.size(), sagged.size());
    double largestDifference = 0.0;
    for (size_t i = 0; i < sagged.size(); ++i)
        largestDifference = std::max(largestDifference, (saggedWithFloor[i] - sagged[i]).norm());
    std::cout << "[ colliders ] cantilever settled with the floor plate as collider: "
              << largestDifference << " m from the shape without it\n";
    EXPECT_LT(largestDifference, 1e-9) << "save settles: the same shape as before";
    ASSERT_TRUE(m_window->openFile(project));
    EXPECT_TRUE(document.hoseDefinition(id)->gravity.enabled);
    EXPECT_TRUE(document.hoseDefinition(id)->torsion.enabled);
    EXPECT_TRUE(document.isCollider("rig", floor));
    while (m_window->gravityTimerActive())
        QTest::qWait(20);
    EXPECT_EQ(document.hose(id)->points(), saggedWithFloor) << "a reload reproduces the sag";

    // Another direction: one undo step, and the hose settles along it.
    document.setSelection(selection);
    settle();
    auto* direction = m_window->findChild<QComboBox*>("gravityDirection");
    ASSERT_TRUE(direction && direction->isEnabled());
    EXPECT_EQ(direction->currentText().toStdString(), "down (−Y)");
    direction->setCurrentIndex(4);
    emit direction->activated(4);
    EXPECT_EQ(document.hoseDefinition(id)->gravity.direction, Vec3(0.0, 0.0, -1.0));
    EXPECT_EQ(document.undoStack()->count(), 1);
    while (m_window->gravityTimerActive())
        QTest::qWait(20);
    EXPECT_LT(document.hose(id)->points().back().z(), sagged.back().z() - 0.05)
        << "the free end swung towards −Z";
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    EXPECT_EQ(document.hoseDefinition(id)->gravity.direction, Vec3(0.0, -1.0, 0.0));
}

/// The entries of the History panel, as a person reads them (its first row is "<empty>").
QStringList historyTexts(MainWindow& window)
{
    auto* history = window.findChild<QUndoView*>("history");
    QStringList texts;
    for (int row = 1; history && row < history->model()->rowCount(); ++row)
        texts << history->model()->index(row, 0).data().toString();
    return texts;
}

using test_support::worstBandExcess;

// Dragging a hose never makes it longer. Twenty mouse drags of a
// point of left-feed, each committed on release, leave its rest length as it was (to 1e-9),
// every segment in its band and the committed hose exactly where the drag left it; saving
// and reopening gives back the same shape and the same length.
TEST_F(MainWindowTest, TwentyMouseDragsKeepTheHoseLengthAndSaveReopenKeepsShapeAndLength)
{
    const QString project = copyOfTestRig("twenty-drags");
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    settle();
    const std::string id = "left-feed";
    const double length = *document.hoseDefinition(id)->length;
    const QPoint directions[] = {{0, -24}, {18, -10}, {-20, 6}, {10, 16}};
    for (int drag = 0; drag < 20; ++drag) {
        const int point = 5 + (drag * 3) % 7; // free points 5 … 11
        const QPoint at = viewport.toWidget(document.hose(id)->point(point));
        this->drag(&viewport, at, at + directions[drag % 4]);
        const Hose& hose = *document.hose(id);
        ASSERT_EQ(document.undoStack()->count(), drag + 1) << "drag " << drag << " committed";
        EXPECT_EQ(document.undoStack()->undoText(),
                  QString("Drag point %1 of left bracket to valve").arg(point));
        EXPECT_NEAR(hose.restLengthTotal(), length, 1e-9) << "drag " << drag;
        EXPECT_EQ(*document.hoseDefinition(id)->length, length) << "drag " << drag;
        EXPECT_LE(worstBandExcess(hose), 1e-9) << "drag " << drag;
    }
    const auto shape = document.hose(id)->points();
    ASSERT_TRUE(m_window->save()) << m_errors.join('\n').toStdString();
    ASSERT_TRUE(m_window->openFile(project)) << m_errors.join('\n').toStdString();
    EXPECT_EQ(*document.hoseDefinition(id)->length, length);
    ASSERT_EQ(document.hose(id)->pointCount(), int(shape.size()));
    for (size_t i = 0; i < shape.size(); ++i)
        EXPECT_NEAR((document.hose(id)->point(int(i)) - shape[i]).norm(), 0.0, 1e-12) << i;
}

// The length is a field of its own; typing a longer one adds slack between the fixed ends.
TEST_F(MainWindowTest, TypingALongerLengthAddsSlackBetweenTheFixedEnds)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("length-field")));
    Document& document = m_window->document();
    selectHose("right-return");
    auto* field = m_window->findChild<QDoubleSpinBox*>("hoseLength");
    ASSERT_TRUE(field);
    const double length = *document.hoseDefinition("right-return")->length;
    EXPECT_NEAR(field->value(), length, 0.0005);
    const Vec3 first = document.hose("right-return")->point(0);
    const Vec3 last = document.hose("right-return")->points().back();
    const double axisBefore = document.hose("right-return")->currentLength();
    field->setFocus();
    field->selectAll();
    QTest::keyClicks(field, QString::number(length + 0.05, 'f', 3));
    QTest::keyClick(field, Qt::Key_Return);
    settle();
    const Hose& hose = *document.hose("right-return");
    EXPECT_NEAR(hose.restLengthTotal(), std::round((length + 0.05) * 1000) / 1000, 1e-9);
    EXPECT_NEAR((hose.point(0) - first).norm(), 0.0, 1e-9) << "fixed ends stay";
    EXPECT_NEAR((hose.points().back() - last).norm(), 0.0, 1e-9);
    EXPECT_GT(hose.currentLength(), axisBefore + 0.04) << "the added length shows as slack";
    EXPECT_LE(worstBandExcess(hose), 1e-9);
    EXPECT_EQ(document.undoStack()->undoText(), "Change length of right bracket to valve");
}

// The wheel over the Properties panel scrolls it; it never changes a value unless the
// field has the keyboard focus.
TEST_F(MainWindowTest, WheelOverPropertiesScrollsThePanelAndChangesNoValue)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("wheel")));
    Document& document = m_window->document();
    m_window->resize(1280, 560); // a panel taller than its dock: it scrolls
    selectHose("left-feed");
    auto* diameter = m_window->findChild<QDoubleSpinBox*>("diameter");
    ASSERT_TRUE(diameter);
    QScrollArea* scroll = nullptr;
    for (QWidget* w = diameter->parentWidget(); w && !scroll; w = w->parentWidget())
        scroll = qobject_cast<QScrollArea*>(w);
    ASSERT_TRUE(scroll);
    settle();
    ASSERT_GT(scroll->verticalScrollBar()->maximum(), 0) << "the panel can scroll";
    scroll->verticalScrollBar()->setValue(0);
    scroll->ensureWidgetVisible(diameter);
    const int scrolledBefore = scroll->verticalScrollBar()->value();
    const double value = diameter->value();
    m_window->viewport().setFocus(); // the field has no keyboard focus
    settle();
    auto wheel = [](QWidget* widget, int notches) {
        const QPointF at(widget->width() / 2.0, widget->height() / 2.0);
        QWheelEvent event(at, widget->mapToGlobal(at), QPoint(), QPoint(0, 120 * notches),
                          Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
        QApplication::sendEvent(widget, &event);
        QApplication::processEvents();
    };
    for (QWidget* field :
         std::initializer_list<QWidget*>{diameter, m_window->findChild<QComboBox*>("preset"),
                                         m_window->findChild<QSlider*>("diameterSlider"),
                                         m_window->findChild<QSpinBox*>("segments")})
        wheel(field, -2); // down: towards the end of the panel
    EXPECT_EQ(diameter->value(), value);
    EXPECT_EQ(document.undoStack()->count(), 0) << "no value changed";
    EXPECT_GT(scroll->verticalScrollBar()->value(), scrolledBefore) << "the panel scrolled";
    // With the keyboard focus the field is being edited: the wheel steps its value.
    scroll->ensureWidgetVisible(diameter);
    QTest::mouseClick(diameter, Qt::LeftButton, {}, QPoint(10, diameter->height() / 2));
    ASSERT_TRUE(diameter->hasFocus());
    wheel(diameter, 1);
    EXPECT_GT(diameter->value(), value);
    EXPECT_EQ(document.undoStack()->count(), 1);
}

// Ctrl+Z after typing a value and pressing Enter undoes the edit of the document; while
// a value is being typed, Ctrl+Z undoes only the typing.
TEST_F(MainWindowTest, CtrlZAfterEnterUndoesTheDocumentEdit)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("ctrl-z")));
    Document& document = m_window->document();
    selectHose("left-feed");
    auto* diameter = m_window->findChild<QDoubleSpinBox*>("diameter");
    const double before = document.hoseDefinition("left-feed")->outerDiameter;
    QTest::mouseClick(diameter, Qt::LeftButton, {}, QPoint(10, diameter->height() / 2));
    diameter->selectAll();
    QTest::keyClicks(diameter, "25");
    QTest::keyClick(diameter, Qt::Key_Return);
    settle();
    ASSERT_NEAR(document.hoseDefinition("left-feed")->outerDiameter, 0.025, 1e-12);
    ASSERT_EQ(document.undoStack()->count(), 1);
    ASSERT_TRUE(diameter->hasFocus());
    QTest::keyClick(diameter, Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document.undoStack()->index(), 0) << "the document's edit was undone";
    EXPECT_EQ(document.hoseDefinition("left-feed")->outerDiameter, before);
    EXPECT_NEAR(diameter->value(), before * 1000.0, 1e-9) << "the field shows it";
    QTest::keyClick(diameter, Qt::Key_Y, Qt::ControlModifier);
    settle();
    EXPECT_NEAR(document.hoseDefinition("left-feed")->outerDiameter, 0.025, 1e-12) << "redone";

    // The name: typed, Enter, Ctrl+Z.
    auto* name = m_window->findChild<QLineEdit*>("hoseName");
    const std::string oldName = document.hoseDefinition("left-feed")->name;
    QTest::mouseClick(name, Qt::LeftButton);
    name->selectAll();
    QTest::keyClicks(name, "feed line");
    // Before Enter, Ctrl+Z is the field's own: the typing goes, the document is untouched.
    QTest::keyClick(name, Qt::Key_Z, Qt::ControlModifier);
    EXPECT_EQ(document.hoseDefinition("left-feed")->name, oldName);
    EXPECT_EQ(name->text().toStdString(), oldName) << "the typing was undone in the field";
    EXPECT_EQ(document.undoStack()->index(), 1);
    name->selectAll();
    QTest::keyClicks(name, "feed line");
    QTest::keyClick(name, Qt::Key_Return);
    settle();
    ASSERT_EQ(document.hoseDefinition("left-feed")->name, "feed line");
    QTest::keyClick(name, Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document.hoseDefinition("left-feed")->name, oldName);
    EXPECT_EQ(name->text().toStdString(), oldName);
}

// Fixing a hose end takes one gesture: click the end point (it is not hidden under the
// route handle there), Ctrl+F (named in the tooltip), click the part. One undo step that says
// what it did; the hose stays selected; the end does not move.
TEST_F(MainWindowTest, FixingAHoseEndTakesOneGesture)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("fix-gesture")));
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    const std::string id = test::addCantilever(document); // fixed at the bracket, end free
    document.undoStack()->clear();
    selectHose(id);
    settle();
    const int end = document.hose(id)->pointCount() - 1;
    const Vec3 endBefore = document.hose(id)->point(end);
    // The route's last point lies exactly on the hose's end: the end point is picked.
    ASSERT_NEAR((document.hoseDefinition(id)->route.back() - endBefore).norm(), 0.0, 1e-12);
    QTest::mouseClick(&viewport, Qt::LeftButton, {}, viewport.toWidget(endBefore));
    ASSERT_EQ(document.selection().hoseId, id);
    ASSERT_EQ(document.selection().rangeFirst, end);
    ASSERT_EQ(document.selection().rangeLast, end);
    EXPECT_EQ(document.selection().routePoint, -1);
    EXPECT_TRUE(m_window->action("actionFix")->toolTip().contains("Ctrl+F"))
        << m_window->action("actionFix")->toolTip().toStdString();
    QTest::keyClick(&viewport, Qt::Key_F, Qt::ControlModifier);
    ASSERT_EQ(viewport.mode(), Viewport::Mode::FixToPart);
    // Click the floor plate (not under a hose).
    std::vector<std::pair<QPoint, ScenePickHit>> floor = topHits("/test-rig/floor_plate");
    ASSERT_FALSE(floor.empty());
    const auto target =
        std::max_element(floor.begin(), floor.end(), [](const auto& a, const auto& b) {
            return a.second.point.z() < b.second.point.z();
        });
    QTest::mouseClick(&viewport, Qt::LeftButton, {}, target->first);
    settle();
    EXPECT_EQ(viewport.mode(), Viewport::Mode::Select);
    ASSERT_EQ(document.hoseDefinition(id)->attachments.size(), 2u);
    const formats::HoseAttachment& fixed = document.hoseDefinition(id)->attachments.back();
    EXPECT_EQ(fixed.node, "/test-rig/floor_plate");
    EXPECT_EQ(fixed.firstPoint, end);
    EXPECT_EQ(fixed.lastPoint, end);
    EXPECT_TRUE(document.hose(id)->isFixed(end));
    EXPECT_NEAR((document.hose(id)->point(end) - endBefore).norm(), 0.0, 1e-9) << "fixed in place";
    EXPECT_EQ(document.undoStack()->count(), 1) << "one gesture, one undo step";
    EXPECT_EQ(historyTexts(*m_window).back(),
              QString("Fix point %1 of cantilever from the left bracket to floor_plate").arg(end));
    EXPECT_EQ(document.selection().hoseId, id) << "clicking the part kept the hose selected";
    screenshot("editor-fix-to-part.png");

    // Shift+click selects the range between the two points clicked.
    QTest::mouseClick(&viewport, Qt::LeftButton, {},
                      viewport.toWidget(document.hose(id)->point(6)));
    QTest::mouseClick(&viewport, Qt::LeftButton, Qt::ShiftModifier,
                      viewport.toWidget(document.hose(id)->point(9)));
    EXPECT_EQ(document.selection().rangeFirst, 6);
    EXPECT_EQ(document.selection().rangeLast, 9);
    QTest::mouseClick(&viewport, Qt::LeftButton, Qt::ShiftModifier,
                      viewport.toWidget(document.hose(id)->point(4)));
    EXPECT_EQ(document.selection().rangeFirst, 4) << "from the point clicked first";
    EXPECT_EQ(document.selection().rangeLast, 6);

    // The fixing controls stay where they are while the panel scrolls.
    QWidget* controls = m_window->findChild<QWidget*>("fixGroup");
    QScrollArea* scroll = nullptr;
    for (QWidget* w = m_window->findChild<QWidget*>("diameter"); w && !scroll;
         w = w->parentWidget())
        scroll = qobject_cast<QScrollArea*>(w);
    ASSERT_TRUE(controls && scroll);
    const QPoint placed = controls->mapTo(m_window.get(), QPoint(0, 0));
    scroll->verticalScrollBar()->setValue(scroll->verticalScrollBar()->maximum());
    settle();
    EXPECT_EQ(controls->mapTo(m_window.get(), QPoint(0, 0)), placed);
    EXPECT_TRUE(controls->isVisible());

    // Ctrl+Z takes the fix back.
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    EXPECT_EQ(document.hoseDefinition(id)->attachments.size(), 1u);
}

// A clip in one gesture: click a hose point, Ctrl+K (named in the tooltip), click the part.
// One undo step; a ring shows the clip; the hose has not moved. Dragging the part with its
// gizmo carries the clip and the hose slides through it: every segment stays in its band, the
// rest length as the author set it, the hose through the clip's centre. Ctrl+Z twice restores
// the hose exactly.
TEST_F(MainWindowTest, AClipAddedWithOneGestureCarriesTheHoseWhenItsPartMoves)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("clip-gesture")));
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    const std::string id = "left-feed";
    selectHose(id);
    settle();
    const std::vector<Vec3> before = document.hose(id)->points();
    const double restLength = document.hose(id)->restLengthTotal();
    QTest::mouseClick(&viewport, Qt::LeftButton, {}, viewport.toWidget(before[8]));
    ASSERT_EQ(document.selection().hoseId, id);
    ASSERT_EQ(document.selection().rangeFirst, 8);
    EXPECT_TRUE(m_window->action("actionAddClip")->toolTip().contains("Ctrl+K"));
    QTest::keyClick(&viewport, Qt::Key_K, Qt::ControlModifier);
    ASSERT_EQ(viewport.mode(), Viewport::Mode::FixToPart);
    std::vector<std::pair<QPoint, ScenePickHit>> floor = topHits("/test-rig/floor_plate");
    ASSERT_FALSE(floor.empty());
    QTest::mouseClick(&viewport, Qt::LeftButton, {}, floor.front().first);
    settle();
    EXPECT_EQ(viewport.mode(), Viewport::Mode::Select);
    ASSERT_EQ(document.hoseDefinition(id)->clips.size(), 1u);
    EXPECT_EQ(document.hoseDefinition(id)->clips[0].node, "/test-rig/floor_plate");
    EXPECT_EQ(document.undoStack()->count(), 1);
    EXPECT_EQ(historyTexts(*m_window).back().toStdString(),
              "Clip point 8 of left bracket to valve to floor_plate");
    const Hose* hose = document.hose(id);
    ASSERT_EQ(hose->attachments().size(), 3u);
    const Hose::Attachment* clip = &hose->attachments()[2];
    EXPECT_TRUE(clip->isClip());
    for (int i = 0; i < hose->pointCount(); ++i)
        EXPECT_NEAR((hose->point(i) - before[static_cast<size_t>(i)]).norm(), 0.0, 1e-9)
            << "adding a clip moves no point";
    screenshot("editor-clip-added.png");

    // The floor plate (selected with the clip) dragged along +X with its gizmo's arrow.
    const int plate = document.scene("rig")->findNode("/test-rig/floor_plate");
    ASSERT_EQ(document.selection().node, plate);
    const Vec3 plateBefore = document.nodeWorldFrame("rig", plate).translation;
    const Vec3 centre = document.partCentre("rig", plate);
    const QPoint a = viewport.toWidget(centre);
    const QPoint b =
        viewport.toWidget(centre + Renderer::gizmoLength(viewport.camera()) * Vec3::UnitX());
    const QPointF direction = QPointF(b - a) / std::hypot(b.x() - a.x(), b.y() - a.y());
    const QPoint grip = a + (b - a) * 0.8;
    const double slideBefore = clip->slide;
    // 25 mm along the arrow (its screen length is gizmoLength metres).
    const double pixelsPerMetre =
        std::hypot(b.x() - a.x(), b.y() - a.y()) / Renderer::gizmoLength(viewport.camera());
    drag(&viewport, grip, grip + (direction * (0.025 * pixelsPerMetre)).toPoint());
    const Vec3 shift = document.nodeWorldFrame("rig", plate).translation - plateBefore;
    EXPECT_GT(shift.x(), 0.01) << "the gizmo moved the plate along +X";
    EXPECT_EQ(document.undoStack()->count(), 2);
    hose = document.hose(id);
    clip = &hose->attachments()[2];
    EXPECT_LE(test_support::worstBandExcess(*hose), 1e-9) << "every segment in its band";
    EXPECT_LE(hose->measureViolation().angleViolation, 1e-9);
    EXPECT_DOUBLE_EQ(hose->restLengthTotal(), restLength) << "the length the author set";
    EXPECT_NEAR(hose->attachmentGap(clip->id), 0.0, 1e-9);
    const Vec3 held = clip->frame.apply(clip->clipCentre);
    EXPECT_NEAR((held - (before[8] + shift)).norm(), 0.0, 1e-9) << "the clip went with the plate";
    const Vec3 p = hose->point(clip->first), d = (hose->point(clip->last) - p).normalized();
    EXPECT_LE(((held - p) - (held - p).dot(d) * d).norm(), 1e-9) << "the hose through it";
    EXPECT_NE(clip->slide, slideBefore) << "the hose slid through the clip";
    std::cout << "[ clip ] plate moved " << shift.x() * 1000.0 << " mm along X; the hose slid "
              << (clip->slide - slideBefore) * 1000.0 << " mm through the clip\n";
    screenshot("editor-clip-slid.png");

    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_TRUE(document.hoseDefinition(id)->clips.empty());
    EXPECT_EQ(document.hose(id)->points(), before) << "undo restores the hose exactly";
}

// The History panel says what each step did and to which object.
TEST_F(MainWindowTest, HistoryEntriesNameWhatAndWhich)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("history")));
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    settle();
    // A hose point dragged with the mouse.
    const QPoint at = viewport.toWidget(document.hose("left-feed")->point(7));
    drag(&viewport, at, at + QPoint(0, -25));
    // The valve moved with the gizmo's X arrow.
    clickTreeItem("valve");
    settle();
    const int valve = document.scene("rig")->findNode("/test-rig/valve");
    const Vec3 centre = document.partCentre("rig", valve);
    const QPoint a = viewport.toWidget(centre);
    const QPoint b =
        viewport.toWidget(centre + Renderer::gizmoLength(viewport.camera()) * Vec3::UnitX());
    const QPoint grip = a + (b - a) * 0.8;
    drag(&viewport, grip, grip + (b - a) / 4);
    // A segment of the cantilever fixed to the left bracket by the panel's button.
    Selection selection = document.selection();
    selection.hoseId = "right-return";
    selection.rangeFirst = 3;
    selection.rangeLast = 4;
    selection.sceneId = "rig";
    selection.node = document.scene("rig")->findNode("/test-rig/bracket_left");
    document.setSelection(selection);
    settle();
    QTest::mouseClick(m_window->findChild<QPushButton*>("fixButton"), Qt::LeftButton);
    // The diameter typed in.
    auto* diameter = m_window->findChild<QDoubleSpinBox*>("diameter");
    QTest::mouseClick(diameter, Qt::LeftButton, {}, QPoint(10, diameter->height() / 2));
    diameter->selectAll();
    QTest::keyClicks(diameter, "18");
    QTest::keyClick(diameter, Qt::Key_Return);
    settle();
    EXPECT_EQ(historyTexts(*m_window),
              (QStringList{"Drag point 7 of left bracket to valve", "Move valve",
                           "Fix points 3–4 of right bracket to valve to bracket_left",
                           "Change diameter of right bracket to valve"}));
}

// (Needs the pinned-span solver, which gives up bends before lengths.) Where the fixed ends
// and their tangents leave no valid shape (the valve turned half round, its inlet pointing
// back, and moved 20 cm towards the left bracket and 10 cm back), the hose keeps its lengths,
// gives up the bend limit, and the kink is shown: a ring in the viewport and a Problems entry
// with the bend radius reached.
TEST_F(MainWindowTest, AKinkedHoseIsMarkedAndListedWithTheRadiusItReached)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("kink")));
    Document& document = m_window->document();
    clickTreeItem("valve");
    settle();
    auto* rotation = m_window->findChild<QDoubleSpinBox*>("partRotationY");
    ASSERT_TRUE(rotation);
    rotation->setValue(rotation->value() + 180.0);
    auto* x = m_window->findChild<QDoubleSpinBox*>("partTranslationX");
    auto* z = m_window->findChild<QDoubleSpinBox*>("partTranslationZ");
    x->setValue(x->value() - 200.0);
    z->setValue(z->value() - 100.0);
    settle();
    const HoseMetrics* metrics = document.hoseMetrics("left-feed");
    ASSERT_TRUE(metrics);
    ASSERT_FALSE(metrics->bendBelowMinimum.empty()) << "the valve turned and moved kinks it";
    EXPECT_EQ(document.lastUpdate("left-feed").status, Status::Infeasible);
    const double minimum = document.hose("left-feed")->material().bendLimit.value;
    m_window->problems().refreshNow();
    bool listed = false;
    for (const Problem& problem : m_window->problems().problems()) {
        if (problem.hoseId != "left-feed" || !problem.text.contains("kinked")) continue;
        listed = true;
        const QRegularExpressionMatch radius =
            QRegularExpression("bend radius ([0-9.]+) mm").match(problem.text);
        ASSERT_TRUE(radius.hasMatch()) << problem.text.toStdString();
        EXPECT_LT(radius.captured(1).toDouble(), minimum * 1000.0) << problem.text.toStdString();
    }
    EXPECT_TRUE(listed);
    selectHose("left-feed");
    m_window->viewport().frameSelection();
    screenshot("editor-kink.png");
    // The ring is drawn around the worst joint: the viewport's pixels there are problem red.
    const QImage image = m_window->viewport().renderToImage();
    const int joint = metrics->smallestBendRadiusJoint;
    const Vec3 centre = document.hose("left-feed")->point(joint);
    const double radius = 2.5 * document.hose("left-feed")->outerRadius();
    int red = 0;
    for (const Vec3& p :
         Renderer::kinkRing(centre, -m_window->viewport().camera().forward(), radius)) {
        const QPoint at = m_window->viewport().toWidget(p) * image.devicePixelRatio();
        if (!image.rect().contains(at)) continue;
        const QColor c = image.pixelColor(at);
        red += c.red() > 200 && c.green() < 120 && c.blue() < 120;
    }
    EXPECT_GT(red, 5) << "the kink ring is drawn";
}

// (Needs the pinned-span solver that keeps every length in its band when an attachment
// moves.) The valve dragged with the gizmo along X from 0 to 0.3 m and back: at every step
// every hose has every segment in its band, and a hose that cannot reach the valve shows how
// much hose it lacks (Problems: "needs N mm more hose", the gap drawn in the viewport); back at
// 0 every hose is where it was, fixed at its points again.
TEST_F(MainWindowTest, TheValveDraggedAlongXAndBackKeepsEveryHoseInItsBandOrShowsItsShortage)
{
    ASSERT_TRUE(m_window->openFile(copyOfTestRig("valve-drag")));
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    settle();
    const auto initialPoints = allPoints(document);
    clickTreeItem("valve");
    settle();
    const int valve = document.scene("rig")->findNode("/test-rig/valve");
    const Vec3 start = document.nodeWorldFrame("rig", valve).translation;
    const Vec3 centre = document.partCentre("rig", valve);
    // The arrow gripped at 0.8 of its length; the mouse goes where the gripped point of the
    // arrow would be drawn after the move (the view is in perspective: equal moves are not
    // equal pixels).
    const Vec3 gripped = centre + 0.8 * Renderer::gizmoLength(viewport.camera()) * Vec3::UnitX();
    const QPoint grip = viewport.toWidget(gripped);
    bool wasShort = false;
    const auto checkEveryHose = [&](double shift) {
        m_window->problems().refreshNow();
        for (const formats::HoseDefinition& definition : document.project().hoses) {
            const Hose& hose = *document.hose(definition.id);
            EXPECT_LE(worstBandExcess(hose), 1e-6)
                << definition.id << " at " << shift << " m: a segment beyond its band";
            double gap = 0.0;
            for (const Hose::Attachment& attachment : hose.attachments())
                gap = std::max(gap, hose.attachmentGap(attachment.id));
            if (gap < 1e-3) continue;
            wasShort = true;
            bool shown = false;
            for (const Problem& problem : m_window->problems().problems())
                shown = shown ||
                        (problem.hoseId == definition.id && problem.text.contains("more hose"));
            EXPECT_TRUE(shown) << definition.id << " at " << shift << " m is " << gap
                               << " m short and the Problems panel does not say so";
        }
    };
    QTest::mousePress(&viewport, Qt::LeftButton, {}, grip);
    const int steps = 30;
    for (int i = 1; i <= 2 * steps; ++i) {
        const double target = 0.3 * (i <= steps ? i : 2 * steps - i) / steps;
        QTest::mouseMove(&viewport, viewport.toWidget(gripped + target * Vec3::UnitX()));
        const double shift = document.nodeWorldFrame("rig", valve).translation.x() - start.x();
        checkEveryHose(shift);
        if (i == steps) {
            EXPECT_GT(shift, 0.28) << "the gizmo took the valve 0.3 m along X";
            screenshot("editor-taut-short.png");
        }
    }
    QTest::mouseRelease(&viewport, Qt::LeftButton, {}, grip);
    settle();
    EXPECT_TRUE(wasShort) << "0.3 m is beyond the hoses' reach";
    EXPECT_NEAR((document.nodeWorldFrame("rig", valve).translation - start).norm(), 0.0, 2e-3);
    // The hoses are back at their fixed points (the part is back within a pixel of its start).
    for (const formats::HoseDefinition& definition : document.project().hoses)
        for (const Hose::Attachment& attachment : document.hose(definition.id)->attachments())
            EXPECT_LT(document.hose(definition.id)->attachmentGap(attachment.id), 1e-9)
                << definition.id;
    EXPECT_EQ(document.undoStack()->count(), 1);
    QTest::keyClick(&viewport, Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(initialPoints, allPoints(document));
}

} // namespace
} // namespace chaintube::editor
