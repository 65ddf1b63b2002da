// The problems panel's clearance check: listed with a threshold in the UI, marked
// for the viewport, and a click selects the hose point and the object. Runs offscreen (the
// panel is a plain list widget; no viewport is created).
#include "problems_panel.h"
#include "test_support.h"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QTest>
#include <gtest/gtest.h>

namespace chaintube::editor {
namespace {

std::vector<int> clearanceRows(const ProblemsPanel& panel)
{
    std::vector<int> rows;
    for (size_t i = 0; i < panel.problems().size(); ++i)
        if (!panel.problems()[i].sceneId.empty()) rows.push_back(int(i));
    return rows;
}

TEST(ClearancePanel, ListsViolationsMarksThemAndSelectsOnClick)
{
    Document document(test::roots());
    document.adopt(readProject(test::samplesDir() / "test-rig.ctproj", test::roots()));
    ProblemsPanel panel(document);
    panel.resize(600, 300);
    panel.show();
    ASSERT_NE(panel.clearanceThreshold(), nullptr);
    EXPECT_EQ(panel.clearanceThreshold()->value(), 5.0);

    // At 5 mm: nothing. The left hose ends in the valve's inlet, but an attachment skips its
    // node and the node's ancestors (cd60963), so the valve is no violation; `chaintube check`
    // agrees (0 violations below 0.005 m).
    panel.refreshNow();
    std::vector<int> rows = clearanceRows(panel);
    EXPECT_TRUE(rows.empty());
    EXPECT_TRUE(document.clearanceMarkers().empty());

    // A larger threshold in the UI finds the floor plate 20 mm under the left hose's end.
    panel.clearanceThreshold()->setValue(50.0);
    panel.refreshNow();
    rows = clearanceRows(panel);
    ASSERT_FALSE(rows.empty());
    const Problem floor = panel.problems()[size_t(rows.front())];
    EXPECT_EQ(floor.hoseId, "left-feed");
    EXPECT_TRUE(floor.text.contains("20.0 mm from /test-rig/floor_plate"))
        << floor.text.toStdString();
    EXPECT_EQ(floor.node, document.scene("rig")->findNode("/test-rig/floor_plate"));
    ASSERT_EQ(document.clearanceMarkers().size(), rows.size());
    EXPECT_EQ(document.clearanceMarkers().front().hoseId, "left-feed");

    // Clicking the row selects the hose's axis point and the floor plate.
    QTest::mouseClick(panel.viewport(), Qt::LeftButton, {},
                      panel.visualItemRect(panel.item(rows.front())).center());
    EXPECT_EQ(document.selection().hoseId, floor.hoseId);
    EXPECT_EQ(document.selection().rangeFirst, floor.firstPoint);
    EXPECT_EQ(document.selection().sceneId, "rig");
    EXPECT_EQ(document.selection().node, floor.node);

    // Switched off: no clearance rows, no markers.
    panel.clearanceEnabled()->setChecked(false);
    EXPECT_TRUE(clearanceRows(panel).empty());
    EXPECT_TRUE(document.clearanceMarkers().empty());
}

} // namespace
} // namespace chaintube::editor
