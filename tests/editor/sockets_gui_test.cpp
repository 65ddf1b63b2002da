// Sockets in the editor, under xvfb-run (platform xcb), driven with QTest mouse and keys on the
// real main window: the "Add Socket" tool button, a click on the valve places a socket on its
// surface (axis the surface normal, in the valve's frame), a tag typed into Properties with
// Enter is one History step, a capture radius of 0 is refused saying why, Ctrl+Z / Ctrl+Y walk
// the steps, Ctrl+S saves and a fresh window opens the socket as it was. No edit moves a hose.
#include "main_window.h"
#include "properties_panel.h"
#include "viewport.h"
#include "window_test.h"

#include <QAction>
#include <QApplication>
#include <QLineEdit>
#include <QStatusBar>
#include <QTest>
#include <QToolBar>
#include <QTreeWidget>
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;

class SocketsGuiTest : public test::WindowTest
{
protected:
    void SetUp() override
    {
        ASSERT_TRUE(openInWindow(m_project)) << m_errors.join('\n').toStdString();
    }
    /// Every hose's axis, to check that no socket edit moves a hose.
    std::vector<Vec3> allAxes()
    {
        std::vector<Vec3> points;
        for (const formats::HoseDefinition& definition : document().project().hoses)
            if (const Hose* hose = document().hose(definition.id))
                for (int i = 0; i < hose->pointCount(); ++i)
                    points.push_back(hose->point(i));
        return points;
    }
    /// A widget point where a pick hits the valve, away from its silhouette.
    QPoint pointOnValve()
    {
        Viewport& viewport = m_window->viewport();
        const int valve = document().scene("rig")->findNode("/test-rig/valve");
        std::vector<QPoint> hits;
        for (int y = 2; y < viewport.height(); y += 4)
            for (int x = 2; x < viewport.width(); x += 4) {
                ScenePickHit hit;
                if (viewport.pickScene(QPointF(x, y), &hit) && hit.node == valve)
                    hits.push_back({x, y});
            }
        if (hits.empty()) return {-1, -1};
        QPoint sum(0, 0);
        for (const QPoint& p : hits)
            sum += p;
        const QPoint mean = sum / int(hits.size());
        // The hit nearest the mean: inside a face, not on an edge.
        QPoint best = hits.front();
        for (const QPoint& p : hits)
            if ((p - mean).manhattanLength() < (best - mean).manhattanLength()) best = p;
        return best;
    }
    void typeInto(QLineEdit* field, const QString& text)
    {
        QTest::mouseClick(field, Qt::LeftButton);
        field->selectAll();
        QTest::keyClicks(field, text);
        QTest::keyClick(field, Qt::Key_Return);
        settle();
    }

    const fs::path m_project = test::copyOfTestRig("sockets-gui");
};

TEST_F(SocketsGuiTest, PlaceTagUndoRedoSaveAndReopen)
{
    const size_t before = document().project().sockets.size();
    ASSERT_EQ(before, 2u) << "the test rig sample has two sockets";
    const std::vector<Vec3> axes = allAxes();
    const int steps = document().undoStack()->count();

    // The tool button, then a click on the valve.
    auto* toolbar = m_window->findChild<QToolBar*>("mainToolbar");
    auto* addSocket = m_window->findChild<QAction*>("actionAddSocket");
    ASSERT_TRUE(toolbar && addSocket);
    QWidget* button = toolbar->widgetForAction(addSocket);
    ASSERT_TRUE(button);
    QTest::mouseClick(button, Qt::LeftButton);
    settle();
    EXPECT_EQ(m_window->viewport().mode(), Viewport::Mode::PlaceSocket);
    const QPoint onValve = pointOnValve();
    ASSERT_GE(onValve.x(), 0) << "the valve is in view";
    QTest::mouseClick(&m_window->viewport(), Qt::LeftButton, {}, onValve);
    settle();
    EXPECT_EQ(m_window->viewport().mode(), Viewport::Mode::Select);
    ASSERT_EQ(document().project().sockets.size(), before + 1);
    const formats::Socket placed = document().project().sockets.back();
    EXPECT_EQ(placed.id, "socket-1");
    EXPECT_EQ(placed.node, "/test-rig/valve");
    EXPECT_EQ(document().selection().socketId, "socket-1");
    EXPECT_EQ(document().undoStack()->count(), steps + 1);
    // On the valve body's surface (a box 80 × 60 × 60 mm about the node), the axis its face's
    // outward normal, in the valve's frame.
    const Vec3 p = placed.position;
    const double onFace =
        std::max({std::abs(p.x()) / 0.04, std::abs(p.y()) / 0.03, std::abs(p.z()) / 0.03});
    EXPECT_NEAR(onFace, 1.0, 1e-6) << p.transpose();
    EXPECT_NEAR(placed.axis.norm(), 1.0, 1e-9);
    EXPECT_NEAR(placed.axis.cwiseAbs().maxCoeff(), 1.0, 1e-6) << placed.axis.transpose();
    EXPECT_GT(placed.axis.dot(p), 0.0) << "out of the part";
    EXPECT_EQ(allAxes(), axes) << "placing a socket moves no hose";
    const auto rows =
        m_window->sceneTree().findItems("socket-1", Qt::MatchExactly | Qt::MatchRecursive);
    EXPECT_EQ(rows.size(), 1) << "listed in the Scene tree";

    // The tag typed into Properties, Enter: one step.
    auto* tag = m_window->properties().findChild<QLineEdit*>("socketTag");
    auto* radius = m_window->properties().findChild<QLineEdit*>("socketRadius");
    ASSERT_TRUE(tag && radius);
    EXPECT_EQ(tag->text(), "plug");
    typeInto(tag, "camlock-19");
    EXPECT_EQ(document().project().findSocket("socket-1")->tag, "camlock-19");
    EXPECT_EQ(document().undoStack()->count(), steps + 2);
    EXPECT_EQ(document().undoStack()->text(steps + 1), "Change socket socket-1");

    // A capture radius of 0 is refused, saying why in the status bar and the field's tooltip.
    typeInto(radius, "0");
    EXPECT_EQ(document().undoStack()->count(), steps + 2) << "nothing pushed";
    EXPECT_EQ(document().project().findSocket("socket-1")->captureRadius, placed.captureRadius);
    EXPECT_TRUE(m_window->statusBar()->currentMessage().contains("capture radius"))
        << m_window->statusBar()->currentMessage().toStdString();
    EXPECT_TRUE(radius->toolTip().contains("capture radius")) << radius->toolTip().toStdString();
    typeInto(radius, "45");
    EXPECT_DOUBLE_EQ(document().project().findSocket("socket-1")->captureRadius, 0.045);
    EXPECT_EQ(document().undoStack()->count(), steps + 3);

    // Ctrl+Z three times: radius, tag, the socket itself; Ctrl+Y three times brings them back.
    QTest::keyClick(&m_window->viewport(), Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document().project().findSocket("socket-1")->captureRadius, placed.captureRadius);
    QTest::keyClick(&m_window->viewport(), Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document().project().findSocket("socket-1")->tag, "plug");
    QTest::keyClick(&m_window->viewport(), Qt::Key_Z, Qt::ControlModifier);
    settle();
    EXPECT_EQ(document().project().findSocket("socket-1"), nullptr);
    EXPECT_EQ(document().project().sockets.size(), before);
    EXPECT_EQ(allAxes(), axes);
    for (int i = 0; i < 3; ++i) {
        QTest::keyClick(&m_window->viewport(), Qt::Key_Y, Qt::ControlModifier);
        settle();
    }
    ASSERT_NE(document().project().findSocket("socket-1"), nullptr);
    formats::Socket expected = placed;
    expected.tag = "camlock-19";
    expected.captureRadius = 0.045;
    EXPECT_EQ(*document().project().findSocket("socket-1"), expected);
    EXPECT_EQ(allAxes(), axes);

    // Ctrl+S, then a fresh window opens it as it was.
    QTest::keyClick(&m_window->viewport(), Qt::Key_S, Qt::ControlModifier);
    settle();
    EXPECT_FALSE(document().isModified());
    m_window.reset();
    ASSERT_TRUE(openInWindow(m_project)) << m_errors.join('\n').toStdString();
    const formats::Socket* loaded = document().project().findSocket("socket-1");
    ASSERT_NE(loaded, nullptr);
    EXPECT_EQ(*loaded, expected);
    EXPECT_EQ(document().project().sockets.size(), before + 1);
}

TEST_F(SocketsGuiTest, AClickOnASocketInTheViewportSelectsIt)
{
    Viewport& viewport = m_window->viewport();
    const auto farFromHoses = [&](const QPoint& at) {
        for (const formats::HoseDefinition& definition : document().project().hoses)
            for (const Vec3& point : document().hose(definition.id)->points())
                if ((viewport.toWidget(point) - at).manhattanLength() < 16) return false;
        return true;
    };
    const formats::Socket* socket = document().project().findSocket("valve-outlet");
    ASSERT_TRUE(socket);
    Vec3 centre, axis;
    ASSERT_TRUE(document().socketWorld(*socket, &centre, &axis));
    const QPoint drawn = viewport.toWidget(centre);
    ASSERT_TRUE(viewport.rect().contains(drawn)) << "the socket is in view";
    QTest::mouseClick(&viewport, Qt::LeftButton, {}, drawn + QPoint(3, -2));
    settle();
    EXPECT_EQ(document().selection().socketId, "valve-outlet");
    EXPECT_TRUE(m_window->statusBar()->currentMessage().contains("valve-outlet"))
        << m_window->statusBar()->currentMessage().toStdString();
    auto* tag = m_window->properties().findChild<QLineEdit*>("socketTag");
    ASSERT_TRUE(tag);
    EXPECT_EQ(tag->text(), "camlock-19") << "Properties shows the clicked socket";
    // Away from every socket (and hose), the click selects what is there instead: the valve.
    const int valve = document().scene("rig")->findNode("/test-rig/valve");
    QPoint away(-1, -1);
    for (int y = 2; y < viewport.height() && away.x() < 0; y += 4)
        for (int x = 2; x < viewport.width() && away.x() < 0; x += 4) {
            ScenePickHit hit;
            if (viewport.pickScene(QPointF(x, y), &hit) && hit.node == valve &&
                (QPoint(x, y) - drawn).manhattanLength() > 30 &&
                viewport.socketAt(QPointF(x, y)).empty() && farFromHoses(QPoint(x, y)))
                away = QPoint(x, y);
        }
    ASSERT_GE(away.x(), 0) << "the valve is in view beside its socket";
    QTest::mouseClick(&viewport, Qt::LeftButton, {}, away);
    settle();
    EXPECT_TRUE(document().selection().socketId.empty())
        << m_window->statusBar()->currentMessage().toStdString();
    EXPECT_EQ(document().selection().node, valve);
}

} // namespace
} // namespace chaintube::editor
