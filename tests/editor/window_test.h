// The fixture of the editor's GUI tests: the real main window on screen under xvfb-run, its
// prompts answered by the test, and the gestures the tests share (settling the event loop,
// mouse drags, clicks in the Scene tree, screenshots).
#pragma once

#include "main_window.h"
#include "problems_panel.h"
#include "test_support.h"
#include "viewport.h"

#include <QApplication>
#include <QImage>
#include <QMessageBox>
#include <QTest>
#include <QTimer>
#include <QTreeWidget>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <gtest/gtest.h>
#include <memory>
#include <string>
#include <vector>

namespace chaintube::editor::test {

/// A copy of the test rig (project and scene file) in a fresh folder `folderName` of the test
/// output, so that saving never touches samples/. Returns the project file.
inline std::filesystem::path copyOfTestRig(const std::string& folderName)
{
    namespace fs = std::filesystem;
    const fs::path folder = outputDir() / folderName;
    fs::remove_all(folder);
    fs::create_directories(folder / "scenes");
    fs::copy_file(samplesDir() / "test-rig.ctproj", folder / "test-rig.ctproj");
    fs::copy_file(samplesDir() / "scenes/test-rig.gltf", folder / "scenes/test-rig.gltf");
    return folder / "test-rig.ctproj";
}

inline QString qtPath(const std::filesystem::path& file)
{
    return QString::fromStdString(file.string());
}

/// Every hose of the document: its live axis points (world metres), in the project's order;
/// empty for a hose that has no live model.
inline std::vector<std::vector<Vec3>> allPoints(const Document& document)
{
    std::vector<std::vector<Vec3>> points;
    for (const auto& hose : document.project().hoses)
        points.push_back(document.hose(hose.id) ? document.hose(hose.id)->points()
                                                : std::vector<Vec3>{});
    return points;
}

/// Calls `drive` every 30 ms while alive (modal dialogs run their own event loops, which
/// process the timer): the way the tests press buttons in real dialogs.
class DialogDriver
{
public:
    explicit DialogDriver(std::function<void()> drive)
    {
        QObject::connect(&m_timer, &QTimer::timeout, std::move(drive));
        m_timer.start(30);
    }

private:
    QTimer m_timer;
};

/// A main window on screen (1280×800). Its questions are answered with `m_answer` and listed in
/// `m_questions`; its error messages are collected in `m_errors`.
class WindowTest : public ::testing::Test
{
protected:
    std::unique_ptr<MainWindow> makeWindow()
    {
        auto window = std::make_unique<MainWindow>(roots());
        window->ask = [this](const QString& title, const QString&, QMessageBox::StandardButtons) {
            m_questions << title;
            return m_answer;
        };
        window->showError = [this](const QString& title, const QString& text) {
            m_errors << title + ": " + text;
        };
        window->resize(1280, 800);
        window->show();
        EXPECT_TRUE(QTest::qWaitForWindowExposed(window.get()));
        activate(window.get());
        return window;
    }
    /// Makes `m_window` (if there is none) and opens `project` in it; false, with the errors
    /// the window showed in `m_errors`, if it could not.
    [[nodiscard]] bool openInWindow(const std::filesystem::path& project)
    {
        if (!m_window) m_window = makeWindow();
        const bool opened = m_window->openFile(qtPath(project));
        settle();
        return opened;
    }
    /// Gives `window` the keyboard: under xvfb no window manager does.
    static void activate(QWidget* window)
    {
        window->activateWindow();
        QApplication::setActiveWindow(window);
        QApplication::processEvents();
    }
    /// Under xvfb no window manager gives the window the focus back when a dialog it opened
    /// closes (the import's progress dialog, shown once an import takes 300 ms, so only on a
    /// loaded machine): with no window active, its window-wide shortcuts (Return finishing a
    /// route, Ctrl+Z) would go nowhere. The window asks for the focus and waits until it has it;
    /// a window or dialog that has it keeps it.
    void takeKeys()
    {
        QApplication::processEvents();
        if (!m_window || QApplication::activeWindow()) return;
        m_window->activateWindow();
        EXPECT_TRUE(QTest::qWaitForWindowActive(m_window.get()));
    }
    /// Lets the window handle what is queued and draws the viewport.
    void settle()
    {
        takeKeys();
        m_window->viewport().repaint();
        QApplication::processEvents();
    }
    Document& document() { return m_window->document(); }
    Viewport& viewport() { return m_window->viewport(); }
    /// Selects a hose of the open document (the properties panel then shows it).
    void selectHose(const std::string& id)
    {
        Selection selection;
        selection.hoseId = id;
        document().setSelection(selection);
        settle();
    }
    void clickTreeItem(const QString& text)
    {
        QTreeWidget& tree = m_window->sceneTree();
        const auto items = tree.findItems(text, Qt::MatchExactly | Qt::MatchRecursive);
        ASSERT_FALSE(items.isEmpty()) << text.toStdString();
        tree.scrollToItem(items.first());
        QTest::mouseClick(tree.viewport(), Qt::LeftButton, {},
                          tree.visualItemRect(items.first()).center());
        settle();
    }
    /// A left-button drag from `from` to `to` in `steps` mouse moves.
    void drag(QWidget* widget, QPoint from, QPoint to, int steps = 8)
    {
        QTest::mousePress(widget, Qt::LeftButton, {}, from);
        for (int i = 1; i <= steps; ++i)
            QTest::mouseMove(widget, from + (to - from) * i / steps);
        QTest::mouseRelease(widget, Qt::LeftButton, {}, to);
        settle();
    }
    /// Saves the window as a person sees it to the test output (CHAINTUBE_UPDATE_SCREENSHOTS=1:
    /// to editor/screenshots too).
    void screenshot(const char* name)
    {
        // What a person sees a moment later: the problems panel recomputes at most every
        // 100 ms after a change, so without this the picture could show an earlier state's list.
        m_window->problems().refreshNow();
        settle();
        const QImage image = m_window->grab().toImage();
        EXPECT_TRUE(image.save(qtPath(outputDir() / name)));
        if (std::getenv("CHAINTUBE_UPDATE_SCREENSHOTS"))
            image.save(QString(CHAINTUBE_SCREENSHOT_DIR) + "/" + name);
    }

    std::unique_ptr<MainWindow> m_window;
    QMessageBox::StandardButton m_answer = QMessageBox::Discard;
    QStringList m_questions;
    QStringList m_errors;
};

} // namespace chaintube::editor::test
