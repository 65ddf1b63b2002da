// The live drag's budget, under xvfb-run (platform xcb), driven with QTest mouse on the real main
// window: a hose point dragged in long mouse moves is moved under UpdateBudget::realtime() while
// the mouse moves (the live hose bounded), and the release converges fully: the committed hose
// has nothing pending, is unbounded again, every segment in its band and every bend within its
// limit.
#include "main_window.h"
#include "viewport.h"
#include "window_test.h"

#include <QApplication>
#include <QTest>
#include <gtest/gtest.h>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;

class DragBudgetGuiTest : public test::WindowTest
{
protected:
    void SetUp() override
    {
        ASSERT_TRUE(openInWindow(test::copyOfTestRig("drag-budget-gui")))
            << m_errors.join('\n').toStdString();
    }
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
