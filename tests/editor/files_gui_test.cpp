// End-to-end tests of the editor's files under xvfb-run (platform xcb), driven with QTest keys
// and mouse clicks on the real main window and its real (Qt) file dialogs: Save As with
// Ctrl+Shift+S into another folder, another root and back, each saved file reopened in a fresh
// window and by the real `chaintube` CLI; the Open and Save dialogs starting in the project's
// folder; a project whose scene is missing opening with the scene marked missing, located
// with Locate… (undoable).
#include "chaintube/editor/commands.h"
#include "chaintube/formats/project.h"
#include "chaintube/test_support/hose_checks.h"
#include "main_window.h"
#include "problems_panel.h"
#include "viewport.h"
#include "window_test.h"

#include <QAbstractButton>
#include <QAction>
#include <QApplication>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QLineEdit>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QPointer>
#include <QPushButton>
#include <QStatusBar>
#include <QTest>
#include <QTimer>
#include <QTreeWidget>
#include <array>
#include <cstdio>
#include <functional>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

namespace chaintube::editor {
namespace {

namespace fs = std::filesystem;
using test::DialogDriver;

/// Runs the real CLI; returns its exit code, `output` gets stdout and stderr.
int runCli(const std::string& arguments, std::string* output)
{
    const std::string command = std::string("\"") + CHAINTUBE_CLI + "\" " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return -1;
    std::array<char, 4096> buffer{};
    size_t got = 0;
    while ((got = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
        output->append(buffer.data(), got);
    const int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Answers the next Qt file dialog named `name`: records the folder it starts in, types
/// `answer` into its file name field and presses Return (or Escape when `answer` is empty).
struct FileDialogAnswer
{
    FileDialogAnswer(QString dialogName, QString typed)
        : name(std::move(dialogName)), answer(std::move(typed))
    {
    }
    QString name;
    QString answer;
    QString startFolder;
    int shown = 0;
    QStringList questions; ///< the texts of the questions it answered
    std::unique_ptr<DialogDriver> driver;
    void arm()
    {
        driver = std::make_unique<DialogDriver>([this] {
            // The dialog asks whether to replace an existing file: yes (the author saves over
            // the project's own file when saving it back).
            if (auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget())) {
                if (shown > 0 && box->isVisible() && !box->property("driven").toBool() &&
                    box->button(QMessageBox::Yes)) {
                    box->setProperty("driven", true);
                    questions << box->text();
                    QPointer<QAbstractButton> yes = box->button(QMessageBox::Yes);
                    QTimer::singleShot(0, [yes] {
                        if (yes) QTest::mouseClick(yes, Qt::LeftButton);
                    });
                }
                return;
            }
            auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
            if (!dialog || dialog->objectName() != name || !dialog->isVisible() ||
                dialog->property("driven").toBool())
                return;
            dialog->setProperty("driven", true);
            ++shown;
            startFolder = dialog->directory().absolutePath();
            QPointer<QLineEdit> field = dialog->findChild<QLineEdit*>("fileNameEdit");
            QPointer<QFileDialog> open = dialog;
            // Pressed once this timer call returns: a question the dialog asks then runs its
            // own event loop, in which this timer must fire again to answer it.
            if (!field || answer.isEmpty()) {
                QTimer::singleShot(0, [open] {
                    if (open) QTest::keyClick(open, Qt::Key_Escape);
                });
                return;
            }
            // The folder chosen (as a click in the dialog's folder list would), the name typed
            // into the file name field, then the dialog's Save/Open button.
            dialog->setDirectory(QFileInfo(answer).absolutePath());
            field->selectAll();
            QTest::keyClicks(field, QFileInfo(answer).fileName());
            QPointer<QPushButton> accept;
            if (auto* box = dialog->findChild<QDialogButtonBox*>("buttonBox"))
                accept = qobject_cast<QPushButton*>(box->buttons().value(0));
            for (QAbstractButton* button :
                 dialog->findChild<QDialogButtonBox*>("buttonBox")->buttons())
                if (dialog->findChild<QDialogButtonBox*>("buttonBox")->buttonRole(button) ==
                    QDialogButtonBox::AcceptRole)
                    accept = qobject_cast<QPushButton*>(button);
            QTimer::singleShot(0, [accept, field] {
                if (accept && accept->isEnabled())
                    QTest::mouseClick(accept, Qt::LeftButton);
                else if (field)
                    QTest::keyClick(field, Qt::Key_Return);
            });
        });
    }
};

class FilesTest : public test::WindowTest
{
protected:
    void SetUp() override { m_window = makeWindow(); }
    /// Presses Ctrl+Shift+S in the viewport and answers the Save As dialog with `file`.
    /// Returns the folder the dialog started in.
    QString saveAsWithKeys(const fs::path& file)
    {
        FileDialogAnswer save{"saveAsDialog", QString::fromStdString(file.string())};
        save.arm();
        activate(m_window.get());
        QTest::keyClick(&m_window->viewport(), Qt::Key_S, Qt::ControlModifier | Qt::ShiftModifier);
        EXPECT_EQ(save.shown, 1) << "Ctrl+Shift+S opens the Save As dialog";
        EXPECT_TRUE(save.questions.isEmpty() || fs::exists(file))
            << "asked " << save.questions.join('\n').toStdString();
        return save.startFolder;
    }
    /// Opens `file` in a fresh window: the scene is found, the hoses are built as in `expected`
    /// (within 1e-9 m); and the CLI checks it with its scene.
    void expectReopens(const fs::path& file, const std::vector<std::vector<Vec3>>& expected)
    {
        auto fresh = makeWindow();
        ASSERT_TRUE(fresh->openFile(QString::fromStdString(file.string())))
            << m_errors.join('\n').toStdString();
        EXPECT_TRUE(fresh->document().missingScenes().empty()) << file;
        EXPECT_TRUE(fresh->document().scene("rig")) << file;
        const auto got = test::allPoints(fresh->document());
        ASSERT_EQ(got.size(), expected.size());
        for (size_t h = 0; h < got.size(); ++h) {
            ASSERT_EQ(got[h].size(), expected[h].size()) << file << " hose " << h;
            for (size_t i = 0; i < got[h].size(); ++i)
                EXPECT_LT((got[h][i] - expected[h][i]).norm(), 1e-9) << file << " hose " << h;
        }
        fresh.reset();
        std::string output;
        const int check = runCli("check \"" + file.string() + "\" --clearance 0.001", &output);
        EXPECT_TRUE(check == 0 || check == 3) << "exit " << check << ": " << output;
        output.clear();
        EXPECT_EQ(runCli("validate \"" + file.string() + "\"", &output), 0) << output;
    }
};

TEST_F(FilesTest, SaveAsWithCtrlShiftSIntoAnotherFolderAnotherRootAndBackReopensEverywhere)
{
    const fs::path original = test::copyOfTestRig("save-as-original");
    ASSERT_TRUE(m_window->openFile(QString::fromStdString(original.string())))
        << m_errors.join('\n').toStdString();
    const auto expected = test::allPoints(m_window->document());
    const std::string originalText = test_support::readText(original);

    // The menu shows the key.
    QAction* saveAs = m_window->action("actionSaveAs");
    ASSERT_TRUE(saveAs);
    EXPECT_EQ(saveAs->shortcut(), QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_S));
    EXPECT_FALSE(saveAs->shortcut().toString(QKeySequence::NativeText).isEmpty());

    // Another folder (created by nobody but the dialog's answer's parent).
    const fs::path elsewhere = test::outputDir() / "save-as-elsewhere/deeper/copy.ctproj";
    fs::remove_all(test::outputDir() / "save-as-elsewhere");
    fs::create_directories(elsewhere.parent_path());
    const QString started = saveAsWithKeys(elsewhere);
    EXPECT_EQ(fs::weakly_canonical(started.toStdString()),
              fs::weakly_canonical(original.parent_path()))
        << "the Save As dialog starts in the project's folder";
    ASSERT_TRUE(fs::exists(elsewhere)) << m_errors.join('\n').toStdString();
    EXPECT_EQ(m_window->document().fileName(), elsewhere);
    EXPECT_FALSE(m_window->document().isModified());
    const formats::Project there = formats::loadProject(elsewhere);
    EXPECT_TRUE(fs::path(there.scenes.at(0).path).is_absolute()) << there.scenes[0].path;
    expectReopens(elsewhere, expected);

    // Another root: a folder under the system's temporary folder, not in the build tree.
    const fs::path otherRoot =
        fs::temp_directory_path() / ("chaintube-save-as-" + std::to_string(::getpid()));
    fs::remove_all(otherRoot);
    fs::create_directories(otherRoot);
    const fs::path onOtherRoot = otherRoot / "moved.ctproj";
    EXPECT_EQ(fs::weakly_canonical(saveAsWithKeys(onOtherRoot).toStdString()),
              fs::weakly_canonical(elsewhere.parent_path()))
        << "the dialog starts where the project now is";
    ASSERT_TRUE(fs::exists(onOtherRoot)) << m_errors.join('\n').toStdString();
    expectReopens(onOtherRoot, expected);

    // And back into its own folder: the file is as it was, the scene path relative again.
    saveAsWithKeys(original);
    EXPECT_EQ(test_support::readText(original), originalText);
    EXPECT_EQ(m_window->document().project().scenes.at(0).path, "scenes/test-rig.gltf");
    expectReopens(original, expected);
    fs::remove_all(otherRoot);
    EXPECT_TRUE(m_errors.isEmpty()) << m_errors.join('\n').toStdString();
}

TEST_F(FilesTest, TheOpenDialogStartsInTheProjectsFolder)
{
    const fs::path project = test::copyOfTestRig("open-dialog-folder");
    ASSERT_TRUE(m_window->openFile(QString::fromStdString(project.string())));
    FileDialogAnswer open{"openDialog", QString()};
    open.arm();
    activate(m_window.get());
    QTest::keyClick(&m_window->viewport(), Qt::Key_O, Qt::ControlModifier);
    ASSERT_EQ(open.shown, 1) << "Ctrl+O opens the Open dialog";
    EXPECT_EQ(fs::weakly_canonical(open.startFolder.toStdString()),
              fs::weakly_canonical(project.parent_path()));
}

TEST_F(FilesTest, AMissingSceneOpensMarkedMissingAndLocateRelinksItUndoably)
{
    // The project without its scenes folder: the scene moved to "found/" beside it.
    const fs::path project = test::copyOfTestRig("missing-scene");
    const fs::path folder = project.parent_path();
    fs::create_directories(folder / "found");
    fs::rename(folder / "scenes/test-rig.gltf", folder / "found/rig-moved.gltf");
    fs::remove(folder / "scenes");

    ASSERT_TRUE(m_window->openFile(QString::fromStdString(project.string())))
        << "never a dead end: " << m_errors.join('\n').toStdString();
    Document& document = m_window->document();
    ASSERT_EQ(document.missingScenes().count("rig"), 1u);
    EXPECT_NE(document.missingScenes().at("rig").find("scenes/test-rig.gltf"), std::string::npos)
        << document.missingScenes().at("rig");
    EXPECT_FALSE(document.scene("rig"));
    ASSERT_EQ(document.hoseCount(), 2);
    EXPECT_FALSE(document.hose(document.project().hoses[0].id)) << "fixed to the missing scene";
    EXPECT_TRUE(m_window->statusBar()->currentMessage().contains("missing"))
        << m_window->statusBar()->currentMessage().toStdString();
    QAction* locate = m_window->action("actionLocateScene");
    ASSERT_TRUE(locate);
    EXPECT_TRUE(locate->isEnabled());
    // The scene tree says so.
    const auto rows = m_window->sceneTree().findItems("rig", Qt::MatchExactly);
    ASSERT_EQ(rows.size(), 1);
    EXPECT_EQ(rows[0]->text(1), "missing");

    // Problems lists it first; a click on the entry asks where it is (Locate…).
    ProblemsPanel& problems = m_window->problems();
    problems.refreshNow();
    QApplication::processEvents();
    ASSERT_FALSE(problems.problems().empty());
    EXPECT_EQ(problems.problems()[0].missingScene, "rig");
    EXPECT_TRUE(problems.problems()[0].text.contains("missing"));
    const QString movedScene = QString::fromStdString((folder / "found/rig-moved.gltf").string());
    FileDialogAnswer answer{"locateSceneDialog", movedScene};
    answer.arm();
    problems.scrollToItem(problems.item(0));
    QTest::mouseClick(problems.viewport(), Qt::LeftButton, {},
                      problems.visualItemRect(problems.item(0)).center());
    ASSERT_EQ(answer.shown, 1) << "a click on the entry opens the Locate dialog";
    EXPECT_EQ(fs::weakly_canonical(answer.startFolder.toStdString()), fs::weakly_canonical(folder));
    ASSERT_TRUE(document.scene("rig")) << m_errors.join('\n').toStdString();
    EXPECT_TRUE(document.missingScenes().empty());
    EXPECT_EQ(document.project().scenes[0].path, "found/rig-moved.gltf")
        << "written relative: the file is inside the project's folder";
    for (const auto& definition : document.project().hoses) {
        const Hose* hose = document.hose(definition.id);
        ASSERT_TRUE(hose) << definition.id << ": " << document.hoseBuildError(definition.id);
        EXPECT_LT(test_support::worstBandExcess(*hose), 1e-6) << definition.id;
    }
    EXPECT_FALSE(locate->isEnabled());
    EXPECT_TRUE(document.isModified());
    EXPECT_EQ(document.undoStack()->undoText().toStdString(), "Locate scene rig");

    // Ctrl+Z: missing again; Ctrl+Y: located again.
    activate(m_window.get());
    QTest::keyClick(&m_window->viewport(), Qt::Key_Z, Qt::ControlModifier);
    EXPECT_EQ(document.missingScenes().count("rig"), 1u);
    EXPECT_FALSE(document.scene("rig"));
    EXPECT_EQ(document.project().scenes[0].path, "scenes/test-rig.gltf");
    EXPECT_FALSE(document.isModified());
    QTest::keyClick(&m_window->viewport(), Qt::Key_Y, Qt::ControlModifier);
    ASSERT_TRUE(document.scene("rig"));
    EXPECT_EQ(document.project().scenes[0].path, "found/rig-moved.gltf");

    // Saved and reopened: found at once.
    ASSERT_TRUE(m_window->save()) << m_errors.join('\n').toStdString();
    auto fresh = makeWindow();
    ASSERT_TRUE(fresh->openFile(QString::fromStdString(project.string())));
    EXPECT_TRUE(fresh->document().missingScenes().empty());
    EXPECT_TRUE(fresh->document().scene("rig"));
    EXPECT_TRUE(m_errors.isEmpty()) << m_errors.join('\n').toStdString();
}

} // namespace
} // namespace chaintube::editor
