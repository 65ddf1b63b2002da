// End-to-end tests of details a designer meets in the first minutes, under xvfb-run (platform
// xcb), driven with QTest keys and mouse on the real main window: parts drawn in colours of
// their own and the selection plain to see; Ctrl snapping a dragged part to whole centimetres
// from its place (so it snaps back onto it); the Scene tree row clickable again after a
// deselect in the viewport; problem labels that never cover one another; a resolution typed
// into the Properties panel carrying the fixed points over (or refused, saying why); a part
// dragged far and back leaving its hoses as a direct move there does.
// Screenshots go to the test output folder (CHAINTUBE_UPDATE_SCREENSHOTS=1: to
// editor/screenshots).
#include "chaintube/editor/commands.h"
#include "chaintube/editor/renderer.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/test_support/hose_checks.h"
#include "main_window.h"
#include "problems_panel.h"
#include "properties_panel.h"
#include "viewport.h"
#include "window_test.h"

#include <QApplication>
#include <QMouseEvent>
#include <QSpinBox>
#include <QStatusBar>
#include <QTest>
#include <QTreeWidget>
#include <cmath>
#include <cstdlib>
#include <gtest/gtest.h>
#include <map>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;
using test_support::worstBandExcess;

class GesturesTest : public test::WindowTest
{
protected:
    void SetUp() override
    {
        const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        ASSERT_TRUE(openInWindow(test::copyOfTestRig("gestures-" + name)))
            << m_errors.join('\n').toStdString();
    }
    int node(const std::string& path) { return document().scene("rig")->findNode(path); }
    /// Mean colour (0–255) of the viewport's pixels where a pick hits node `node` of the rig
    /// (8 px grid); `count` receives how many there were.
    QColor meanColourOf(int node, int* count)
    {
        settle();
        const QImage frame = viewport().grabFramebuffer();
        const double ratio = frame.width() / double(viewport().width());
        double r = 0, g = 0, b = 0;
        int n = 0;
        for (int y = 4; y < viewport().height(); y += 8)
            for (int x = 4; x < viewport().width(); x += 8) {
                ScenePickHit hit;
                if (!viewport().pickScene(QPointF(x, y), &hit) || hit.sceneId != "rig" ||
                    hit.node != node)
                    continue;
                const QColor c = frame.pixelColor(int(x * ratio), int(y * ratio));
                r += c.red(), g += c.green(), b += c.blue(), ++n;
            }
        *count = n;
        return n ? QColor(int(r / n), int(g / n), int(b / n)) : QColor();
    }
    static double distance(const QColor& a, const QColor& b)
    {
        return std::hypot(a.red() - b.red(), a.green() - b.green(), a.blue() - b.blue());
    }
    /// A drag of the selected part's X arrow by `metres` (gripped at 0.8 of its length; the
    /// mouse goes where the gripped point would be drawn after the move), holding `modifiers`.
    void dragArrowX(int part, double metres, Qt::KeyboardModifiers modifiers)
    {
        dragArrow(part, 0, metres, modifiers);
    }
    /// The same along world axis `axis` (0 x, 1 y, 2 z).
    void dragArrow(int part, int axis, double metres, Qt::KeyboardModifiers modifiers)
    {
        const Vec3 centre = document().partCentre("rig", part);
        const Vec3 direction = Vec3::Unit(axis);
        const Vec3 gripped = centre + 0.8 * Renderer::gizmoLength(viewport().camera()) * direction;
        const QPoint grip = viewport().toWidget(gripped);
        QTest::mousePress(&viewport(), Qt::LeftButton, modifiers, grip);
        QPoint at = grip;
        for (int i = 1; i <= 10; ++i) {
            at = viewport().toWidget(gripped + metres * i / 10.0 * direction);
            // (QTest::mouseMove sends no modifiers: Ctrl is held through the whole drag.)
            QMouseEvent move(QEvent::MouseMove, QPointF(at), viewport().mapToGlobal(QPointF(at)),
                             Qt::NoButton, Qt::LeftButton, modifiers);
            QApplication::sendEvent(&viewport(), &move);
        }
        QTest::mouseRelease(&viewport(), Qt::LeftButton, modifiers, at);
        settle();
    }
};

TEST_F(GesturesTest, TheValveIsDrawnDistinctFromTheFloorAndPlainlySelected)
{
    const int valve = node("/test-rig/valve");
    const int floor = node("/test-rig/floor_plate");
    ASSERT_GE(valve, 0);
    ASSERT_GE(floor, 0);
    EXPECT_NE(Renderer::partColour(*document().scene("rig"), valve),
              Renderer::partColour(*document().scene("rig"), floor));
    int valvePixels = 0, floorPixels = 0;
    const QColor valveColour = meanColourOf(valve, &valvePixels);
    const QColor floorColour = meanColourOf(floor, &floorPixels);
    ASSERT_GT(valvePixels, 5) << "the valve is in view";
    ASSERT_GT(floorPixels, 5) << "the floor is in view";
    EXPECT_GT(distance(valveColour, floorColour), 40.0)
        << "valve " << valveColour.name().toStdString() << ", floor "
        << floorColour.name().toStdString();

    clickTreeItem("valve");
    ASSERT_EQ(document().selection().node, valve);
    int selectedPixels = 0;
    const QColor selected = meanColourOf(valve, &selectedPixels);
    EXPECT_GT(distance(selected, valveColour), 40.0)
        << "selected " << selected.name().toStdString() << ", not selected "
        << valveColour.name().toStdString();
    EXPECT_GT(selected.blue(), valveColour.blue() + 20) << "tinted azure";
    screenshot("editor-valve-selected.png");
}

TEST_F(GesturesTest, CtrlSnapsADraggedPartToWholeCentimetresFromItsPlaceSoItSnapsBackOntoIt)
{
    const int valve = node("/test-rig/valve");
    clickTreeItem("valve");
    ASSERT_EQ(document().selection().node, valve);
    const Vec3 start = document().nodeWorldFrame("rig", valve).translation;
    // A free drag: some millimetres, not whole centimetres.
    dragArrowX(valve, 0.037, Qt::NoModifier);
    const double free = document().nodeWorldFrame("rig", valve).translation.x() - start.x();
    EXPECT_GT(free, 0.02);
    EXPECT_GT(std::abs(std::remainder(free, 0.01)), 1e-4) << free << " m: not snapped";
    // With Ctrl, a drag of about a centimetre more: the offset from its place is whole
    // centimetres, not the free offset plus a centimetre.
    dragArrowX(valve, 0.012, Qt::ControlModifier);
    const double snapped = document().nodeWorldFrame("rig", valve).translation.x() - start.x();
    EXPECT_NEAR(std::remainder(snapped, 0.01), 0.0, 1e-9) << snapped << " m";
    // With Ctrl, back by about what it moved: onto its place exactly.
    dragArrowX(valve, -snapped + 0.002, Qt::ControlModifier);
    EXPECT_LT((document().nodeWorldFrame("rig", valve).translation - start).norm(), 1e-9)
        << "snapped back onto its place";
    for (const formats::HoseDefinition& definition : document().project().hoses) {
        const Hose& hose = *document().hose(definition.id);
        for (const Hose::Attachment& attachment : hose.attachments())
            EXPECT_LT(hose.attachmentGap(attachment.id), 1e-9) << definition.id;
        EXPECT_LE(worstBandExcess(hose), 1e-6) << definition.id;
    }
    EXPECT_EQ(document().undoStack()->count(), 3);
}

// The valve dragged with the gizmo 0.29 m along X, where both hoses are taut, short of it and
// kinked, then back to 2 mm from its place in a second drag: every hose is within its bend
// limits again (no Problems entry) and within 1 mm of the hose built straight at that pose
// (formats::buildHose: what typing the pose, the export and the CLI give). Ctrl+Z twice
// restores the first shape exactly.
TEST_F(GesturesTest, AHoseIsTheSameAfterItsPartWentFarAndCameBackAsWhenMovedThereDirectly)
{
    const int valve = node("/test-rig/valve");
    std::map<std::string, std::vector<Vec3>> initial;
    for (const formats::HoseDefinition& definition : document().project().hoses)
        initial[definition.id] = document().hose(definition.id)->points();
    clickTreeItem("valve");
    ASSERT_EQ(document().selection().node, valve);
    const Vec3 start = document().nodeWorldFrame("rig", valve).translation;
    dragArrowX(valve, 0.29, Qt::NoModifier);
    const double out = document().nodeWorldFrame("rig", valve).translation.x() - start.x();
    EXPECT_GT(out, 0.27);
    bool kinkedOut = false;
    for (const formats::HoseDefinition& definition : document().project().hoses) {
        const Hose& hose = *document().hose(definition.id);
        kinkedOut = kinkedOut || hose.measureViolation().angleViolation > 1e-6;
        EXPECT_LE(worstBandExcess(hose), 1e-6) << definition.id << " out";
    }
    EXPECT_TRUE(kinkedOut) << "0.29 m out, a hose's bends give way";
    dragArrowX(valve, -(out - 0.002), Qt::NoModifier);
    const double back = document().nodeWorldFrame("rig", valve).translation.x() - start.x();
    EXPECT_NEAR(back, 0.002, 1e-3);
    m_window->problems().refreshNow();
    for (const formats::HoseDefinition& definition : document().project().hoses) {
        const Hose& hose = *document().hose(definition.id);
        const UpdateResult state = hose.measureViolation();
        EXPECT_LE(state.angleViolation, 1e-9) << definition.id << ": a bend stays kinked";
        EXPECT_LE(worstBandExcess(hose), 1e-6) << definition.id;
        for (const Problem& problem : m_window->problems().problems())
            EXPECT_NE(problem.hoseId, definition.id) << problem.text.toStdString();
        const Hose direct =
            formats::buildHose(document().project(), definition, document().scenes());
        ASSERT_EQ(direct.pointCount(), hose.pointCount());
        double farthest = 0.0;
        for (int i = 0; i < hose.pointCount(); ++i)
            farthest = std::max(farthest, (hose.point(i) - direct.point(i)).norm());
        EXPECT_LE(farthest, 1e-3) << definition.id << ": not the shape of the direct move";
    }
    EXPECT_EQ(document().undoStack()->count(), 2);
    QTest::keyClick(&viewport(), Qt::Key_Z, Qt::ControlModifier);
    QTest::keyClick(&viewport(), Qt::Key_Z, Qt::ControlModifier);
    settle();
    for (const formats::HoseDefinition& definition : document().project().hoses)
        EXPECT_EQ(document().hose(definition.id)->points(), initial[definition.id])
            << definition.id;
}

TEST_F(GesturesTest, TheSceneTreeRowSelectsAgainAfterADeselectInTheViewport)
{
    const int valve = node("/test-rig/valve");
    clickTreeItem("valve");
    ASSERT_EQ(document().selection().node, valve);
    // A click on the empty sky deselects.
    QPoint sky;
    for (int y = 4; y < viewport().height() && sky.isNull(); y += 8)
        for (int x = 4; x < viewport().width() && sky.isNull(); x += 8) {
            ScenePickHit hit;
            // The top rows first: sky, away from the hoses and the valve's gizmo.
            if (!viewport().pickScene(QPointF(x, y), &hit) &&
                (QPoint(x, y) - viewport().toWidget(document().partCentre("rig", valve)))
                        .manhattanLength() > 250)
                sky = QPoint(x, y);
        }
    ASSERT_FALSE(sky.isNull());
    QTest::mouseClick(&viewport(), Qt::LeftButton, {}, sky);
    settle();
    ASSERT_EQ(document().selection().node, -1) << "deselected";
    EXPECT_FALSE(m_window->sceneTree().currentItem()) << "no row stays highlighted";
    // The same row again.
    clickTreeItem("valve");
    EXPECT_EQ(document().selection().node, valve);
    EXPECT_EQ(document().selection().sceneId, "rig");
}

TEST_F(GesturesTest, TwoHosesShortAtTheSamePartGetLabelsThatDoNotOverlap)
{
    const int valve = node("/test-rig/valve");
    clickTreeItem("valve");
    // 0.3 m along Z: both hoses short of it, one also kinked; their labels would fall on one
    // another beside the valve.
    dragArrow(valve, 2, 0.3, Qt::NoModifier);
    settle();
    int shortLabels = 0;
    const auto& labels = viewport().problemLabels();
    for (const auto& [text, rect] : labels)
        if (text.contains("short")) ++shortLabels;
    EXPECT_GE(shortLabels, 2) << "both hoses are short of the valve 0.3 m away";
    EXPECT_GE(labels.size(), 3u) << "and one is kinked";
    for (size_t a = 0; a < labels.size(); ++a)
        for (size_t b = a + 1; b < labels.size(); ++b)
            EXPECT_FALSE(labels[a].second.intersects(labels[b].second))
                << labels[a].first.toStdString() << " overlaps " << labels[b].first.toStdString();
}

TEST_F(GesturesTest, AResolutionTypedWithEnterCarriesTheFixedPointsOverAndCtrlZRestoresIt)
{
    Selection selection;
    selection.hoseId = "left-feed";
    document().setSelection(selection);
    settle();
    const std::vector<Vec3> before = document().hose("left-feed")->points();
    const formats::HoseDefinition original = *document().hoseDefinition("left-feed");
    ASSERT_EQ(original.segmentCount, 16);
    auto* segments = m_window->findChild<QSpinBox*>("segments");
    ASSERT_TRUE(segments);
    const auto type = [&](const char* text) {
        activate(m_window.get());
        QTest::mouseClick(segments, Qt::LeftButton, {}, QPoint(10, segments->height() / 2));
        segments->selectAll();
        QTest::keyClicks(segments, text);
        QTest::keyClick(segments, Qt::Key_Return);
        settle();
    };

    type("12");
    const formats::HoseDefinition* definition = document().hoseDefinition("left-feed");
    ASSERT_EQ(definition->segmentCount, 12);
    const Hose* hose = document().hose("left-feed");
    ASSERT_TRUE(hose) << document().hoseBuildError("left-feed");
    EXPECT_EQ(hose->segmentCount(), 12);
    ASSERT_EQ(definition->attachments.size(), 2u);
    EXPECT_EQ(definition->attachments[0].firstPoint, 0);
    EXPECT_EQ(definition->attachments[0].lastPoint, 1);
    EXPECT_EQ(definition->attachments[1].firstPoint, 11);
    EXPECT_EQ(definition->attachments[1].lastPoint, 12);
    for (const Hose::Attachment& attachment : hose->attachments())
        EXPECT_LT(hose->attachmentGap(attachment.id), 1e-9) << "the fixed points still hold";
    EXPECT_LE(worstBandExcess(*hose), 1e-6) << "every segment in its band";
    EXPECT_NEAR((hose->points().front() - before.front()).norm(), 0.0, 1e-9);
    EXPECT_NEAR((hose->points().back() - before.back()).norm(), 0.0, 1e-9);
    EXPECT_EQ(document().undoStack()->count(), 1) << "one step";
    EXPECT_TRUE(document().undoStack()->undoText().contains("resolution"));

    // 20 as well (more segments than it had at first).
    type("20");
    ASSERT_EQ(document().hose("left-feed")->segmentCount(), 20);
    EXPECT_EQ(document().hoseDefinition("left-feed")->attachments[1].lastPoint, 20);
    EXPECT_LE(worstBandExcess(*document().hose("left-feed")), 1e-6);

    // 1 segment cannot hold two fixed ranges: refused, saying why, where the author looks.
    const int steps = document().undoStack()->count();
    type("1");
    EXPECT_EQ(document().hoseDefinition("left-feed")->segmentCount, 20);
    EXPECT_EQ(segments->value(), 20) << "the field shows the document's value again";
    EXPECT_EQ(document().undoStack()->count(), steps) << "no history entry";
    const QString status = m_window->statusBar()->currentMessage();
    EXPECT_TRUE(status.contains("too few")) << status.toStdString();
    EXPECT_TRUE(segments->toolTip().contains("too few")) << segments->toolTip().toStdString();
    EXPECT_TRUE(m_window->properties().lastRefusal().contains("too few"));

    // Ctrl+Z twice: the hose as it was.
    activate(m_window.get());
    QTest::keyClick(&viewport(), Qt::Key_Z, Qt::ControlModifier);
    QTest::keyClick(&viewport(), Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(*document().hoseDefinition("left-feed"), original);
    EXPECT_EQ(document().hose("left-feed")->points(), before);
}

} // namespace
} // namespace chaintube::editor
