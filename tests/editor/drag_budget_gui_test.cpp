// The live drag's budget, under xvfb-run (platform xcb), driven with QTest mouse on the real main
// window: a hose point dragged in long mouse moves is moved under UpdateBudget::realtime() while
// the mouse moves (the live hose bounded), and the release converges fully: the committed hose
// has nothing pending, is unbounded again, every segment in its band and every bend within its
// limit.
#include "main_window.h"
#include "test_support.h"
#include "viewport.h"

#include <QApplication>
#include <QTest>
#include <gtest/gtest.h>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;

class DragBudgetGuiTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        fs::remove_all(m_folder);
        fs::create_directories(m_folder / "scenes");
        fs::copy_file(test::samplesDir() / "test-rig.ctproj", m_folder / "test-rig.ctproj");
        fs::copy_file(test::samplesDir() / "scenes/test-rig.gltf",
                      m_folder / "scenes/test-rig.gltf");
        m_window = std::make_unique<MainWindow>(test::roots());
        m_window->ask = [](const QString&, const QString&, QMessageBox::StandardButtons) {
            return QMessageBox::Discard;
        };
        m_window->showError = [this](const QString& title, const QString& text) {
            m_errors << title + ": " + text;
        };
        m_window->resize(1280, 800);
        m_window->show();
        ASSERT_TRUE(QTest::qWaitForWindowExposed(m_window.get()));
        m_window->activateWindow();
        QApplication::setActiveWindow(m_window.get());
        QApplication::processEvents();
        ASSERT_TRUE(
            m_window->openFile(QString::fromStdString((m_folder / "test-rig.ctproj").string())))
            << m_errors.join('\n').toStdString();
        settle();
    }
    void settle()
    {
        QApplication::processEvents();
        m_window->viewport().repaint();
        QApplication::processEvents();
    }

    fs::path m_folder = test::outputDir() / "drag-budget-gui";
    std::unique_ptr<MainWindow> m_window;
    QStringList m_errors;
};

TEST_F(DragBudgetGuiTest, AHosePointDraggedInLongMovesIsBoundedLiveAndFullyConvergedOnRelease)
{
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    const std::string id = "left-feed";
    const int point = 8;
    ASSERT_TRUE(document.hose(id));
    EXPECT_FALSE(document.hose(id)->budget().bounded()) << "unbounded until a drag";
    const Vec3 before = document.hose(id)->point(point);
    const QPoint from = viewport.toWidget(before);
    const QPoint to = from + QPoint(30, -90);
    QTest::mousePress(&viewport, Qt::LeftButton, {}, from);
    // Three long moves: each a grab of at most the realtime budget.
    for (int i = 1; i <= 3; ++i) {
        QTest::mouseMove(&viewport, from + (to - from) * i / 3);
        const Hose* live = document.hose(id);
        ASSERT_TRUE(live);
        EXPECT_EQ(live->budget().newtonSteps, UpdateBudget::kRealtimeNewtonSteps) << "move " << i;
        EXPECT_EQ(live->heldPoint(), point) << "move " << i;
        const UpdateResult v = live->measureViolation();
        EXPECT_LE(v.lengthViolation, 1e-9) << "move " << i;
        EXPECT_LE(v.angleViolation, 1e-9) << "move " << i;
    }
    QTest::mouseRelease(&viewport, Qt::LeftButton, {}, to);
    settle();
    ASSERT_EQ(document.undoStack()->count(), 1) << m_errors.join('\n').toStdString();
    const Hose& committed = *document.hose(id);
    EXPECT_FALSE(committed.pending());
    EXPECT_FALSE(committed.budget().bounded()) << "the committed hose is unbounded";
    const UpdateResult v = committed.measureViolation();
    EXPECT_LE(v.lengthViolation, 1e-9);
    EXPECT_LE(v.angleViolation, 1e-9);
    for (int s = 0; s < committed.segmentCount(); ++s) {
        const double length = (committed.point(s + 1) - committed.point(s)).norm();
        EXPECT_GE(length, committed.minLength(s) * (1.0 - 1e-9)) << "segment " << s;
        EXPECT_LE(length, committed.maxLength(s) * (1.0 + 1e-9)) << "segment " << s;
    }
    EXPECT_GT((committed.point(point) - before).norm(), 0.01) << "the drag moved the point";
}

} // namespace
} // namespace chaintube::editor
