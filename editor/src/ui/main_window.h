// ChainTube editor — the main window: menus and shortcuts, the viewport, the scene tree,
// properties, problems, motions and history docks; files (new/open/save/save as, recent files,
// the unsaved-changes prompt, autosave and crash recovery), scene import and export.
#pragma once

#include "chaintube/editor/document.h"

#include <QElapsedTimer>
#include <QMainWindow>
#include <QMessageBox>
#include <QTimer>
#include <functional>
#include <memory>

class QAction;
class QMenu;
class QTreeWidget;
class QTreeWidgetItem;
class QUndoView;

namespace chaintube::editor {

class ExportDialog;
class MotionsPanel;
class ProblemsPanel;
class PropertiesPanel;
class Viewport;

/// The named roots the editor resolves "root:path" scene paths with: scenes = the build's
/// CHAINTUBE_SCENES_DIR, overridden by the settings entries roots/<name>, overridden by the
/// command line's `--root NAME=DIR` options (given here). Malformed options set *error.
formats::NamedRoots editorRoots(const QStringList& rootOptions, QString* error);

class MainWindow : public QMainWindow
{
    Q_OBJECT
public:
    explicit MainWindow(formats::NamedRoots roots, QWidget* parent = nullptr);
    ~MainWindow() override;

    Document& document() { return *m_document; }
    Viewport& viewport() { return *m_viewport; }
    PropertiesPanel& properties() { return *m_properties; }
    ProblemsPanel& problems() { return *m_problems; }
    MotionsPanel& motions() { return *m_motions; }
    QTreeWidget& sceneTree() { return *m_sceneTree; }
    /// The export dialog (created on first use, shown modeless).
    ExportDialog& exportDialog();

    /// How the window asks a question (unsaved changes, recovery). Tests replace it; the
    /// default shows a QMessageBox.
    std::function<QMessageBox::StandardButton(const QString& title, const QString& text,
                                              QMessageBox::StandardButtons buttons)>
        ask;
    /// How errors are shown (default: a QMessageBox); tests collect them.
    std::function<void(const QString& title, const QString& text)> showError;

    /// Opens a project (asks about unsaved changes first; offers a newer autosave).
    bool openFile(const QString& path);
    bool save();
    bool saveAs(const QString& path);
    void newProject();
    /// Imports a scene file into the project: reads it (progress dialog, cancellable), shows
    /// the Import dialog (the units and up axis the reader assumed, changeable, and where the
    /// scene goes), reads it again if the author changed units or axis, and adds it placed
    /// (SceneImportSettings::placement) in one undo step.
    bool importSceneFile(const QString& path);
    /// Locate… for a scene whose file is missing (Document::missingScenes): reads `file` (asked
    /// for in the dialog "locateSceneDialog" when empty) with the scene's import settings and
    /// points the scene at it, written as a project path (formats::projectPathFor), in one undo
    /// step (RelinkSceneCommand). False, with a message, if cancelled or unreadable.
    bool locateScene(const std::string& sceneId, QString file = {});
    /// Asks to save unsaved changes; false if the user cancelled.
    bool maybeSave();
    /// Writes the autosave now if the document is modified; returns its path ("" if none).
    QString autosaveNow();
    /// Autosave period (default 30 s); restarts the timer.
    void setAutosaveInterval(int milliseconds) { m_autosaveTimer.start(milliseconds); }
    /// Where the autosave of the current document goes.
    QString autosavePath() const;
    QAction* action(const QString& objectName) const;
    /// Period of the live gravity timer, milliseconds; each tick advances gravity by the time
    /// since the last (Document::advanceGravity), so the hoses fall at the speed of time.
    static constexpr int kGravityIntervalMs = 16;
    bool gravityTimerActive() const { return m_gravityTimer.isActive(); }
    /// At start-up without a project: offers the untitled autosave if one exists.
    bool recoverUntitled();

protected:
    void closeEvent(QCloseEvent* event) override;

private:
    void createActions();
    void createDocks();
    void onDocumentChanged(const ChangeEvent& event);
    void rebuildSceneTree();
    /// World offset that puts `scene` where ImportDialog::Placement `placement` says.
    Vec3 placementOf(const formats::ImportedScene& scene, int placement) const;
    /// After a part moved: names the hoses that could not follow it (Document::lastUpdate).
    void reportHosesThatCannotFollow();
    void syncTreeSelection();
    void updateTitle();
    void addRecentFile(const QString& path);
    void rebuildRecentMenu();
    void onRouteFinished(const std::vector<Vec3>& route, double outerDiameter);
    void deleteSelection();
    void insertRoutePoint();
    void removeAutosave();
    /// Before opening: every "root:path" scene of the project whose root is unknown (or does
    /// not hold the scene) gets its folder from the author (askRootFolder); the answer is kept
    /// in the settings (roots/<name>) and in the document's roots. Returns false if the author
    /// cancelled a question.
    bool resolveNamedRoots(const QString& projectPath);
    /// Where the Open, Save As and Import dialogs start: the project's folder, else (an
    /// untitled project) the folder last used in one of them, else the working folder.
    QString dialogFolder() const;
    /// Qt's own file dialog (object name `name`) starting in dialogFolder(): an existing file
    /// to open, or (`save`) a project file to write, ".ctproj" added when the name has no
    /// extension. "" if cancelled.
    QString askFile(const QString& name, const QString& title, const QString& filter, bool save);
    /// The folder dialog (object name "rootFolderDialog"); "" if cancelled.
    QString askRootFolder(const QString& rootName, const QString& scenePath);
    bool offerRecovery(const QString& projectPath, const QString& autosave);

    std::unique_ptr<Document> m_document;
    Viewport* m_viewport = nullptr;
    PropertiesPanel* m_properties = nullptr;
    ProblemsPanel* m_problems = nullptr;
    MotionsPanel* m_motions = nullptr;
    QTreeWidget* m_sceneTree = nullptr;
    QUndoView* m_history = nullptr;
    ExportDialog* m_exportDialog = nullptr;
    QMenu* m_recentMenu = nullptr;
    QTimer m_autosaveTimer;
    /// Advances hoses with gravity on (Document::advanceGravity) while any is settling; stopped
    /// when all are settled, so an idle editor does no work.
    QTimer m_gravityTimer;
    QElapsedTimer m_gravityClock; ///< time since the gravity timer's last tick or start
    bool m_syncingTree = false;
};

} // namespace chaintube::editor
