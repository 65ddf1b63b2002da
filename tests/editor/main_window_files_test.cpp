// The main window's files and dialogs under xvfb-run: a named root asked for, scene import with
// its units, progress and cancel, recent files, the unsaved-changes prompt, the window layout
// across restarts and autosave recovery.
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

TEST_F(MainWindowTest, AnUnknownNamedRootIsAskedForInADialogAndRemembered)
{
    // The test rig's project, its scene path naming a root "rigparts" nobody has defined.
    const fs::path folder = outputDir() / "named-root";
    fs::remove_all(folder);
    fs::create_directories(folder / "project");
    fs::create_directories(folder / "parts");
    fs::copy_file(samplesDir() / "scenes/test-rig.gltf", folder / "parts/test-rig.gltf");
    formats::Project rig = formats::loadProject(samplesDir() / "test-rig.ctproj");
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
    const fs::path folder = outputDir() / "import-dialog";
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
    const fs::path folder = outputDir() / "import-progress";
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
    const fs::path folder = outputDir() / "import-progress";
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
    const QString first = qtPath(copyOfTestRig("recent-a"));
    const QString second = qtPath(copyOfTestRig("recent-b"));
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
        ASSERT_TRUE(m_window->openFile(qtPath(copyOfTestRig("recent-" + std::to_string(i)))));
    EXPECT_EQ(menu->actions().size(), 8);
    QSettings().remove("recentFiles");
}

TEST_F(MainWindowTest, TheUnsavedChangesPromptIsARealDialogThatCanCancelOrDiscard)
{
    // A window with its own question box (not the fixture's answering function).
    m_window.reset();
    auto window = std::make_unique<MainWindow>(roots());
    window->resize(1280, 800);
    window->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(window.get()));
    ASSERT_TRUE(window->openFile(qtPath(copyOfTestRig("prompt"))));
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
    auto restarted = std::make_unique<MainWindow>(roots());
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
    const QString project = qtPath(copyOfTestRig("recovery"));
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

} // namespace
} // namespace chaintube::editor
