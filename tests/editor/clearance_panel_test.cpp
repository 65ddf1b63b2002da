// The problems panel's clearance check (issue 7 §3): listed with a threshold in the UI, marked
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

    // At 5 mm: the left hose runs into the valve (the same finding as `chaintube check`).
    panel.refreshNow();
    std::vector<int> rows = clearanceRows(panel);
    ASSERT_FALSE(rows.empty());
    const Problem valve = panel.problems()[size_t(rows.front())];
    EXPECT_EQ(valve.hoseId, "left-feed");
    EXPECT_TRUE(valve.text.contains("/test-rig/valve")) << valve.text.toStdString();
    EXPECT_EQ(valve.node, document.scene("rig")->findNode("/test-rig/valve"));
    ASSERT_EQ(document.clearanceMarkers().size(), rows.size());
    EXPECT_EQ(document.clearanceMarkers().front().hoseId, "left-feed");

    // A larger threshold in the UI finds more (the floor plate 20 mm away).
    panel.clearanceThreshold()->setValue(50.0);
    panel.refreshNow();
    EXPECT_GT(clearanceRows(panel).size(), rows.size());
    bool floor = false;
    for (int row : clearanceRows(panel)) floor |= panel.problems()[size_t(row)].text.contains("floor_plate");
    EXPECT_TRUE(floor);

    // Clicking the valve row selects the hose's axis point and the valve.
    panel.refreshNow();
    rows = clearanceRows(panel);
    const Problem first = panel.problems()[size_t(rows.front())];
    QTest::mouseClick(panel.viewport(), Qt::LeftButton, {},
                      panel.visualItemRect(panel.item(rows.front())).center());
    EXPECT_EQ(document.selection().hoseId, first.hoseId);
    EXPECT_EQ(document.selection().rangeFirst, first.firstPoint);
    EXPECT_EQ(document.selection().sceneId, "rig");
    EXPECT_EQ(document.selection().node, first.node);

    // Switched off: no clearance rows, no markers.
    panel.clearanceEnabled()->setChecked(false);
    EXPECT_TRUE(clearanceRows(panel).empty());
    EXPECT_TRUE(document.clearanceMarkers().empty());
}

} // namespace
} // namespace chaintube::editor
