// End-to-end tests of the Motions dock under xvfb-run (platform xcb): open the motion rig,
// scrub its lever and carriage with keys and a mouse drag on the slider handle as a person
// would, measure the hoses the parts carry (every segment in its band, the attached end where
// the motion puts it), check that scrubbing is a preview (no undo step, the project unchanged)
// and that "Project pose" gives back the project's shape exactly. Screenshots go to the test
// output folder (CHAINTUBE_UPDATE_SCREENSHOTS=1: to editor/screenshots).
#include "chaintube/editor/commands.h"
#include "chaintube/editor/motion_sweep.h"
#include "chaintube/export/sweep.h"
#include "chaintube/formats/motion.h"
#include "main_window.h"
#include "motion_plot.h"
#include "motions_panel.h"
#include "problems_panel.h"
#include "viewport.h"
#include "window_test.h"

#include <QApplication>
#include <QDoubleSpinBox>
#include <QLabel>
#include <QListWidget>
#include <QPushButton>
#include <QSignalSpy>
#include <QSlider>
#include <QStyle>
#include <QStyleOptionSlider>
#include <QTest>
#include <cmath>
#include <cstdlib>
#include <gtest/gtest.h>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

class MotionsTest : public test::WindowTest
{
protected:
    void SetUp() override
    {
        ASSERT_TRUE(openInWindow(test::samplesDir() / "motion-rig.ctproj"))
            << m_errors.join('\n').toStdString();
    }
    const formats::PartMotion& motion(int i) { return document().project().motions.at(size_t(i)); }
    /// The centre of a slider's handle, in the slider's coordinates.
    static QPoint handleCentre(QSlider* slider)
    {
        QStyleOptionSlider option;
        option.initFrom(slider);
        option.orientation = slider->orientation();
        option.minimum = slider->minimum();
        option.maximum = slider->maximum();
        option.sliderPosition = slider->sliderPosition();
        option.sliderValue = slider->value();
        option.singleStep = slider->singleStep();
        option.pageStep = slider->pageStep();
        return slider->style()
            ->subControlRect(QStyle::CC_Slider, &option, QStyle::SC_SliderHandle, slider)
            .center();
    }
    /// Every segment of the live hose within its stretch band (relative tolerance 1e-9).
    static void expectEverySegmentInItsBand(const Hose& hose)
    {
        for (int s = 0; s < hose.segmentCount(); ++s) {
            const double length = (hose.point(s + 1) - hose.point(s)).norm();
            EXPECT_LE(length, hose.maxLength(s) * (1.0 + 1e-9)) << "segment " << s;
            EXPECT_GE(length, hose.minLength(s) * (1.0 - 1e-9)) << "segment " << s;
        }
    }
    /// Waits for sweeps to finish until `done` holds (a sweep runs on a worker thread).
    void waitForSweep(const std::function<bool()>& done)
    {
        QSignalSpy finished(&m_window->motions(), &MotionsPanel::sweepFinished);
        for (int wait = 0; wait < 20 && !done(); ++wait)
            finished.wait(30000);
        settle();
        ASSERT_TRUE(done()) << m_window->motions().sweepError().toStdString();
    }
    /// The Problems panel's rows as a person reads them.
    QStringList problemTexts()
    {
        m_window->problems().refreshNow();
        QStringList texts;
        for (int row = 0; row < m_window->problems().count(); ++row)
            texts << m_window->problems().item(row)->text();
        return texts;
    }
    void clickProblem(int row)
    {
        QListWidget& list = m_window->problems();
        list.scrollToItem(list.item(row));
        QTest::mouseClick(list.viewport(), Qt::LeftButton, Qt::NoModifier,
                          list.visualItemRect(list.item(row)).center());
        settle();
    }
};

TEST_F(MotionsTest, ScrubbingTheLeverWithKeysMovesItsHoseEndWithItAndChangesNoProjectState)
{
    ASSERT_EQ(document().project().motions.size(), 2u);
    const int lever = document().scene("rig")->findNode("/motion-rig/lever");
    const std::string fingerprint = document().stateFingerprint();
    const std::vector<Vec3> before = document().hose("lever-feed")->points();
    const std::vector<Vec3> carriageBefore = document().hose("carriage-feed")->points();
    const formats::Mat4 leverWorld = document().nodeWorldTransform("rig", lever);

    QSlider* slider = m_window->motions().slider(0);
    ASSERT_NE(slider, nullptr);
    EXPECT_EQ(slider->objectName(), "motionSlider_lever");
    EXPECT_EQ(m_window->motions().valueLabel(0)->text(), "0.0°");
    slider->setFocus();
    for (int press = 0; press < 7; ++press) // 7 pages of 5°
        QTest::keyClick(slider, Qt::Key_PageUp);
    settle();
    const double value = 35.0 * kPi / 180.0;
    EXPECT_EQ(m_window->motions().valueLabel(0)->text(), "35.0°");
    ASSERT_EQ(document().motionPreview().size(), 2u);
    EXPECT_NEAR(document().motionPreview()[0], value, 1e-12);
    EXPECT_EQ(document().motionPreview()[1], 0.0);

    // The lever turned 35° about its hinge axis, and the hose end fixed to it went along.
    const Frame turn = formats::motionFrame(motion(0), value);
    const formats::Mat4 leverNow = document().nodeWorldTransform("rig", lever);
    formats::Mat4 expected = formats::Mat4::Identity();
    expected.topLeftCorner<3, 3>() = turn.rotation.toRotationMatrix();
    expected.topRightCorner<3, 1>() = turn.translation;
    expected = expected * leverWorld;
    EXPECT_LT((leverNow - expected).cwiseAbs().maxCoeff(), 1e-12);
    const Hose& hose = *document().hose("lever-feed");
    const Vec3 end = turn.apply(before.back());
    EXPECT_LT((hose.point(hose.segmentCount()) - end).norm(), 1e-9)
        << "the end fixed to the lever is " << (hose.point(hose.segmentCount()) - end).norm()
        << " m from where the hinge puts it";
    EXPECT_LT((hose.point(0) - before.front()).norm(), 1e-12) << "the pillar end stays";
    EXPECT_GT((hose.point(8) - before[8]).norm(), 0.01) << "the middle of the hose moved";
    expectEverySegmentInItsBand(hose);
    EXPECT_EQ(document().hose("carriage-feed")->points(), carriageBefore);

    // A preview: no undo step, not modified, the project file's content unchanged.
    EXPECT_EQ(document().undoStack()->count(), 0);
    EXPECT_FALSE(document().isModified());
    EXPECT_EQ(document().stateFingerprint(), fingerprint);
    screenshot("editor-motion-scrub.png");

    // "Project pose" puts the lever back and builds the hose as the project gives it.
    QTest::mouseClick(m_window->motions().resetButton(), Qt::LeftButton);
    settle();
    EXPECT_EQ(slider->value(), 0);
    EXPECT_EQ(m_window->motions().valueLabel(0)->text(), "0.0°");
    EXPECT_TRUE(document().motionPreview().empty());
    EXPECT_EQ(document().nodeWorldTransform("rig", lever), leverWorld);
    EXPECT_EQ(document().hose("lever-feed")->points(), before);
    EXPECT_EQ(document().stateFingerprint(), fingerprint);
}

TEST_F(MotionsTest, DraggingTheCarriageHandleSlidesTheCarriageAndItsHoseFollows)
{
    const std::vector<Vec3> before = document().hose("carriage-feed")->points();
    QSlider* slider = m_window->motions().slider(1);
    ASSERT_NE(slider, nullptr);
    const QPoint grab = handleCentre(slider);
    const int travel = slider->width() / 4;
    QTest::mousePress(slider, Qt::LeftButton, Qt::NoModifier, grab);
    for (int dx = 4; dx <= travel; dx += 4) // a person's drag: many small moves
        QTest::mouseMove(slider, grab + QPoint(dx, 0));
    QTest::mouseRelease(slider, Qt::LeftButton, Qt::NoModifier, grab + QPoint(travel, 0));
    settle();
    const double value = document().motionPreview().at(1);
    // A quarter of the groove is about a quarter of the 100 mm range.
    EXPECT_GT(value, 0.015);
    EXPECT_LT(value, 0.035);
    EXPECT_EQ(value, motionValueOfTick(motion(1), slider->value()));
    EXPECT_EQ(m_window->motions().valueLabel(1)->text().toStdString(),
              formatMotionValue(motion(1), value));
    const Hose& hose = *document().hose("carriage-feed");
    const Vec3 end = before.back() + value * Vec3::UnitX();
    EXPECT_LT((hose.point(hose.segmentCount()) - end).norm(), 1e-9);
    EXPECT_LT((hose.point(0) - before.front()).norm(), 1e-12);
    expectEverySegmentInItsBand(hose);

    // An edit ends the preview: the parts go back to the project's pose first.
    Selection selection;
    selection.hoseId = "carriage-feed";
    document().setSelection(selection);
    formats::HoseDefinition renamed = *document().hoseDefinition("carriage-feed");
    renamed.name = "renamed";
    document().undoStack()->push(
        makeSetHoseDefinition(document(), "carriage-feed", renamed, MergeId::None, "Rename"));
    settle();
    EXPECT_TRUE(document().motionPreview().empty());
    EXPECT_EQ(slider->value(), 0);
    EXPECT_EQ(document().hose("carriage-feed")->points(), before);
}

TEST_F(MotionsTest, EachHoseIsPlottedOverTheSweepTheCliRunsWithItsLimitsAndTheSliderMarked)
{
    // The clearance typed into the Problems panel is the sweep's threshold.
    QDoubleSpinBox* threshold = m_window->problems().clearanceThreshold();
    threshold->setFocus();
    threshold->selectAll();
    QTest::keyClicks(threshold, "40");
    QTest::keyClick(threshold, Qt::Key_Return);
    MotionsPanel& motions = m_window->motions();
    waitForSweep([&] {
        return motions.report() && motions.report()->clearanceThreshold == 0.04 &&
               !motions.sweepRunning();
    });

    exporting::SweepOptions options;
    options.clearanceThreshold = 0.04;
    const exporting::SweepReport cli =
        exporting::sweepMotions(document().project(), document().scenes(), options);
    ASSERT_EQ(cli.steps.size(), 51u); // 1 + lead-in 10 + 2 × 20, as `chaintube check --sweep`
    ASSERT_EQ(motions.plots().size(), 3u);
    for (size_t h = 0; h < 3; ++h) {
        const MotionPlotSeries& plotted = motions.plots()[h]->series();
        EXPECT_EQ(plotted.hoseId, cli.hoses[h].hoseId);
        // The way out: the lead-in's last step (t = 0) and the 20 steps to t = 1; the way back:
        // 20 steps to t = 0. Each value is the CLI sweep's at that step.
        ASSERT_EQ(plotted.out.t.size(), 21u);
        ASSERT_EQ(plotted.back.t.size(), 20u);
        EXPECT_EQ(plotted.out.t.front(), 0.0);
        EXPECT_EQ(plotted.out.t.back(), 1.0);
        EXPECT_EQ(plotted.back.t.back(), 0.0);
        for (size_t i = 0; i < 21; ++i) {
            EXPECT_EQ(plotted.out.bendRadius[i], cli.hoses[h].bendRadiusSeries[10 + i]);
            EXPECT_EQ(plotted.out.clearance[i], cli.hoses[h].clearanceSeries[10 + i]);
        }
        for (size_t i = 0; i < 20; ++i) {
            EXPECT_EQ(plotted.back.bendRadius[i], cli.hoses[h].bendRadiusSeries[31 + i]);
            EXPECT_EQ(plotted.back.clearance[i], cli.hoses[h].clearanceSeries[31 + i]);
        }
        EXPECT_EQ(plotted.clearanceThreshold, 0.04);
    }
    EXPECT_EQ(motions.plots()[0]->series().minBendRadius, 0.12); // rubber hose
    EXPECT_EQ(motions.plots()[1]->series().minBendRadius, 0.08); // cable bundle
    EXPECT_EQ(motions.plots()[2]->series().hoseId, "carriage-cable");
    EXPECT_EQ(motions.plots()[2]->series().minBendRadius, 0.08);
    // The carriage's hose end rests 32 mm above the base plate at every step.
    for (double clearance : motions.plots()[1]->series().out.clearance)
        EXPECT_NEAR(clearance, 0.032, 1e-6);

    // The marker follows the slider: 35° of the lever's −28.6° … 45.8°.
    EXPECT_NEAR(*motions.plots()[0]->marker(), 0.5 / 1.3, 1e-12); // value 0 on the way
    QSlider* lever = motions.slider(0);
    lever->setFocus();
    for (int press = 0; press < 7; ++press)
        QTest::keyClick(lever, Qt::Key_PageUp);
    settle();
    const double t = (35.0 * kPi / 180.0 + 0.5) / 1.3;
    EXPECT_NEAR(*motions.plots()[0]->marker(), t, 1e-12);
    EXPECT_NEAR(*motions.plots()[1]->marker(), t, 1e-12);

    // Problems names the motion values where the sweep found the clearance broken.
    EXPECT_TRUE(problemTexts().contains(
        "pillar to carriage — sweep, lever at 0.0°, carriage at 0.0 mm: 32.0 mm from "
        "/motion-rig/base_plate (clearance 40.0 mm), on 51 of 51 steps"))
        << problemTexts().join('\n').toStdString();
    EXPECT_EQ(problemTexts().filter("pillar to lever tip — sweep").size(), 0);
    screenshot("editor-motion-plots.png");
}

TEST_F(MotionsTest, ASweepProblemNamesWhereTheBendBreaksAndAClickPreviewsThePartsThere)
{
    MotionsPanel& motions = m_window->motions();
    waitForSweep([&] { return motions.report().has_value() && !motions.sweepRunning(); });
    EXPECT_TRUE(m_window->motions().findings().empty());

    // A stiffer hose to the carriage: braided steel bends no tighter than 165 mm, and the
    // carriage hose comes down to about 102 mm over the motions.
    formats::HoseDefinition stiffer = *document().hoseDefinition("carriage-feed");
    stiffer.material = formats::PresetName{"braided steel hose"};
    document().undoStack()->push(
        makeSetHoseDefinition(document(), "carriage-feed", stiffer, MergeId::None, "Material"));
    settle();
    ASSERT_EQ(motions.plots().size(), 3u);
    EXPECT_TRUE(motions.plots()[1]->stale()) << "an edit makes the plots out of date";
    waitForSweep([&] {
        return motions.report() && motions.report()->hoses[1].minBendRadius == 0.165 &&
               !motions.sweepRunning();
    });
    EXPECT_FALSE(motions.plots()[1]->stale());
    EXPECT_EQ(motions.plots()[1]->series().minBendRadius, 0.165);

    const exporting::HoseSweep& swept = motions.report()->hoses[1];
    ASSERT_TRUE(swept.bendViolated());
    const std::vector<double>& where =
        motions.report()->steps[size_t(swept.smallestBendRadiusStep)].values;
    const std::string expected = "pillar to carriage — sweep, " +
                                 describeMotionValues(document().project().motions, where) +
                                 ": bend radius ";
    const QStringList texts = problemTexts();
    int row = -1;
    for (int i = 0; i < texts.size(); ++i)
        if (texts[i].toStdString().rfind(expected, 0) == 0) row = i;
    ASSERT_GE(row, 0) << texts.join('\n').toStdString();
    EXPECT_TRUE(texts[row].contains(" < 165.0 mm, on ")) << texts[row].toStdString();

    // A click on it moves the parts to where it happens (a preview) and selects the joint.
    clickProblem(row);
    ASSERT_EQ(document().motionPreview().size(), 2u);
    EXPECT_EQ(document().motionPreview(), where);
    EXPECT_EQ(document().selection().hoseId, "carriage-feed");
    EXPECT_EQ(document().selection().rangeFirst, swept.smallestBendRadiusJoint);
    EXPECT_EQ(motions.slider(1)->value(),
              motionTickOfValue(document().project().motions[1], where[1]));
    EXPECT_EQ(motions.valueLabel(0)->text().toStdString(),
              formatMotionValue(document().project().motions[0], where[0]));
    expectEverySegmentInItsBand(*document().hose("carriage-feed"));
    screenshot("editor-motion-problem.png");
}

// The plots' value labels and axis text are never cut off: each has room inside its plot, in
// the window as it opens and in a narrow one.
TEST_F(MotionsTest, ThePlotsAxisLabelsHaveRoomInThePlot)
{
    MotionsPanel& motions = m_window->motions();
    waitForSweep([&] { return motions.report().has_value() && !motions.sweepRunning(); });
    for (const QSize size : {QSize(1280, 800), QSize(1000, 700)}) {
        m_window->resize(size);
        settle();
        const auto plots = m_window->findChildren<MotionPlot*>();
        ASSERT_FALSE(plots.isEmpty());
        for (MotionPlot* plot : plots) {
            if (!plot->isVisible()) continue;
            const QFontMetrics metrics = plot->fontMetrics();
            const auto labels = plot->labels();
            ASSERT_GE(labels.size(), 5u) << "two value axes and the motion axis";
            for (const MotionPlot::Label& label : labels) {
                EXPECT_TRUE(plot->rect().contains(label.rect))
                    << label.text.toStdString() << " leaves the plot of "
                    << plot->objectName().toStdString();
                const QRect needs = metrics.boundingRect(label.rect, label.flags, label.text);
                EXPECT_LE(needs.width(), label.rect.width()) << label.text.toStdString();
                EXPECT_LE(needs.height(), label.rect.height()) << label.text.toStdString();
            }
        }
    }
}

} // namespace
} // namespace chaintube::editor
