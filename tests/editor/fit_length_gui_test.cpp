// "Fit length…" in the real main window under xvfb-run, driven as a person would: click a hose
// of the motion-rig sample in the scene tree, Ctrl+L, type a length in the dialog, Enter; then
// measure the hose (its length as set, every segment in its band, its ends where they were) and
// undo it with Ctrl+Z. The screenshot goes to the test output folder
// (CHAINTUBE_UPDATE_SCREENSHOTS=1: to editor/screenshots).
#include "chaintube/editor/commands.h"
#include "chaintube/test_support/hose_checks.h"
#include "fit_length_dialog.h"
#include "main_window.h"
#include "test_support.h"
#include "viewport.h"

#include <QDoubleSpinBox>
#include <QLabel>
#include <QPainter>
#include <QScreen>
#include <QTest>
#include <QTimer>
#include <QTreeWidget>
#include <QUndoStack>
#include <chaintube/export/fit_length.h>
#include <cstdlib>
#include <gtest/gtest.h>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;

/// The motion-rig sample in a fresh folder (so that nothing touches samples/).
QString copyOfMotionRig()
{
    const fs::path folder = test::outputDir() / "fit-length";
    fs::remove_all(folder);
    fs::create_directories(folder / "scenes");
    fs::copy_file(test::samplesDir() / "motion-rig.ctproj", folder / "motion-rig.ctproj");
    fs::copy_file(test::samplesDir() / "scenes/motion-rig.gltf", folder / "scenes/motion-rig.gltf");
    return QString::fromStdString((folder / "motion-rig.ctproj").string());
}

/// The window and the dialog over it, as the screen shows them.
void screenshot(QWidget& window, QWidget& dialog, const char* name)
{
    QImage image = window.grab().toImage();
    {
        QPainter painter(&image);
        const QPoint at = dialog.mapToGlobal(QPoint(0, 0)) - window.mapToGlobal(QPoint(0, 0));
        painter.drawImage(at, dialog.grab().toImage());
    }
    const QString file = QString::fromStdString((test::outputDir() / name).string());
    EXPECT_TRUE(image.save(file));
    if (std::getenv("CHAINTUBE_UPDATE_SCREENSHOTS"))
        image.save(QString(CHAINTUBE_SCREENSHOT_DIR) + "/" + name);
}

TEST(FitLengthGui, CtrlLTypeALengthEnterSetsItInOneStepAndCtrlZUndoesIt)
{
    MainWindow window(test::roots());
    QStringList errors;
    window.showError = [&](const QString& title, const QString& text) {
        errors << title + ": " + text;
    };
    window.resize(1280, 800);
    window.show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
    window.activateWindow();
    QApplication::setActiveWindow(&window);
    ASSERT_TRUE(window.openFile(copyOfMotionRig())) << errors.join('\n').toStdString();
    Document& document = window.document();
    const std::string id = "lever-feed";

    // Select the hose by clicking its row in the scene tree.
    QTreeWidget& tree = window.sceneTree();
    const auto items = tree.findItems("pillar to lever tip", Qt::MatchExactly | Qt::MatchRecursive);
    ASSERT_FALSE(items.isEmpty());
    tree.scrollToItem(items.first());
    QTest::mouseClick(tree.viewport(), Qt::LeftButton, {},
                      tree.visualItemRect(items.first()).center());
    ASSERT_EQ(document.selection().hoseId, id);
    window.viewport().frameSelection();

    // What the dialog should offer: the library's fit of the same hose.
    const exporting::LengthFit expected =
        exporting::fitHoseLength(document.project(), document.scenes(), document.hoseIndex(id), {});
    ASSERT_TRUE(expected.valid) << expected.reason;
    const double before = *document.hoseDefinition(id)->length;
    const std::vector<Vec3> shapeBefore = document.hose(id)->points();
    const int undoIndex = document.undoStack()->index();
    // A length inside the range, not the dialog's default: typed with the keyboard.
    const double chosen =
        std::round((expected.shortest + 0.25 * (expected.longest - expected.shortest)) * 1000.0) /
        1000.0;
    ASSERT_NE(chosen, FitLengthDialog::defaultLength(expected));

    bool shown = false;
    QString rangeText;
    double offeredDefault = 0.0, offeredMinimum = 0.0, offeredMaximum = 0.0;
    QTimer driver;
    QObject::connect(&driver, &QTimer::timeout, [&] {
        auto* dialog = window.findChild<FitLengthDialog*>("fitLengthDialog");
        if (!dialog || !dialog->isVisible() || shown) return;
        shown = true;
        auto* value = dialog->findChild<QDoubleSpinBox*>("fitLengthValue");
        rangeText = dialog->findChild<QLabel*>("fitLengthRange")->text();
        offeredDefault = value->value();
        offeredMinimum = value->minimum();
        offeredMaximum = value->maximum();
        screenshot(window, *dialog, "editor-fit-length.png");
        // The value is selected and has the focus: type over it, then Enter.
        QTest::keyClicks(value, QString::number(chosen, 'f', 3));
        QTest::keyClick(value, Qt::Key_Return);
    });
    driver.start(30);
    QTest::keyClick(&window.viewport(), Qt::Key_L, Qt::ControlModifier);
    driver.stop();
    QApplication::processEvents();
    ASSERT_TRUE(shown) << errors.join('\n').toStdString();
    EXPECT_TRUE(errors.isEmpty()) << errors.join('\n').toStdString();
    EXPECT_TRUE(rangeText.contains(QString::number(expected.shortest, 'f', 3)))
        << rangeText.toStdString();
    EXPECT_DOUBLE_EQ(offeredDefault, FitLengthDialog::defaultLength(expected));
    EXPECT_GE(offeredMinimum, expected.shortest);
    EXPECT_LE(offeredMaximum, expected.longest);

    // One undo step that sets the length: every rest length chosen / segments, every segment in
    // its band, the ends where their parts hold them.
    EXPECT_EQ(document.undoStack()->index(), undoIndex + 1);
    EXPECT_EQ(document.undoStack()->undoText(), "Fit length of pillar to lever tip");
    EXPECT_DOUBLE_EQ(*document.hoseDefinition(id)->length, chosen);
    const Hose& hose = *document.hose(id);
    EXPECT_NEAR(hose.restLengthTotal(), chosen, 1e-9);
    for (int s = 0; s < hose.segmentCount(); ++s)
        EXPECT_NEAR(hose.restLength(s), chosen / hose.segmentCount(), 1e-12) << s;
    EXPECT_LE(test_support::worstBandExcess(hose), 1e-9);
    EXPECT_NEAR((hose.point(0) - shapeBefore.front()).norm(), 0.0, 1e-9);
    EXPECT_NEAR((hose.points().back() - shapeBefore.back()).norm(), 0.0, 1e-9);

    // Ctrl+Z: the length and the shape as before. (The dialog has closed: the window is the
    // active one again, as it is for a person.)
    QApplication::setActiveWindow(&window);
    window.viewport().setFocus();
    QTest::keyClick(&window.viewport(), Qt::Key_Z, Qt::ControlModifier);
    QApplication::processEvents();
    EXPECT_EQ(document.undoStack()->index(), undoIndex);
    EXPECT_DOUBLE_EQ(*document.hoseDefinition(id)->length, before);
    ASSERT_EQ(document.hose(id)->pointCount(), static_cast<int>(shapeBefore.size()));
    for (size_t i = 0; i < shapeBefore.size(); ++i)
        EXPECT_NEAR((document.hose(id)->point(static_cast<int>(i)) - shapeBefore[i]).norm(), 0.0,
                    1e-12)
            << i;
}

TEST(FitLengthGui, AHoseWithAFreeEndIsRefusedWithAMessage)
{
    MainWindow window(test::roots());
    QStringList errors;
    window.showError = [&](const QString& title, const QString& text) {
        errors << title + ": " + text;
    };
    window.show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
    ASSERT_TRUE(window.openFile(
        QString::fromStdString((test::samplesDir() / "single-hose.ctproj").string())));
    Document& document = window.document();
    Selection selection;
    selection.hoseId = document.project().hoses.at(0).id;
    document.setSelection(selection);
    const int undoIndex = document.undoStack()->index();
    window.activateWindow();
    QApplication::setActiveWindow(&window);
    window.viewport().setFocus();
    QTest::keyClick(&window.viewport(), Qt::Key_L, Qt::ControlModifier);
    ASSERT_EQ(errors.size(), 1);
    EXPECT_TRUE(errors[0].contains("needs both ends fixed")) << errors[0].toStdString();
    EXPECT_EQ(document.undoStack()->index(), undoIndex);
}

} // namespace
} // namespace chaintube::editor
