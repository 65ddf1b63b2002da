// The main window's panels and edits under xvfb-run: properties refusing invalid values and a
// slider drag as one undo step, the problems panel, gravity, torsion and colliders, mouse drags
// keeping the hose's length, Enter then Ctrl+Z, fixing and clipping with one gesture, the
// history's names, a kinked hose marked, a part dragged away and back.
#include "chaintube/editor/commands.h"
#include "chaintube/editor/export_integration.h"
#include "chaintube/editor/route_layout.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/route.h"
#include "chaintube/test_support/hose_checks.h"
#include "export_dialog.h"
#include "import_dialog.h"
#include "main_window.h"
#include "main_window_test.h"
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

TEST_F(MainWindowTest, PropertiesRefuseInvalidValuesAndASliderDragIsOneStep)
{
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("properties"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("blank"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("profile-fields"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("problems"))));
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
    const QString project = qtPath(copyOfTestRig("gravity"));
    ASSERT_TRUE(m_window->openFile(project));
    Document& document = m_window->document();
    const std::string id = addCantilever(document);
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
    const double expected = lowestReachableY(*document.hose(id));
    const double drop = authored[1].y() - expected;
    EXPECT_NEAR(lowestY(sagged), expected, 0.02 * drop);
    EXPECT_LT(lowestY(sagged), lowestY(authored) - 0.1);
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
    const QString project = qtPath(copyOfTestRig("twenty-drags"));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("length-field"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("wheel"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("ctrl-z"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("fix-gesture"))));
    Document& document = m_window->document();
    Viewport& viewport = m_window->viewport();
    const std::string id = addCantilever(document); // fixed at the bracket, end free
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("clip-gesture"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("history"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("kink"))));
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
    ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("valve-drag"))));
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
