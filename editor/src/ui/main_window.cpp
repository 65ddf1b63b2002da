#include "main_window.h"

#include "chaintube/editor/commands.h"
#include "chaintube/editor/route_layout.h"
#include "chaintube/formats/atomic_file.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/formats/scene_import.h"
#include "chaintube/route.h"
#include "export_dialog.h"
#include "fit_length_dialog.h"
#include "import_dialog.h"
#include "import_runner.h"
#include "motions_panel.h"
#include "problems_panel.h"
#include "properties_panel.h"
#include "viewport.h"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QHeaderView>
#include <QMenuBar>
#include <QScrollArea>
#include <QSettings>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTextStream>
#include <QToolBar>
#include <QTreeWidget>
#include <QUndoView>
#include <QVBoxLayout>
#include <fstream>
#include <limits>
#include <sstream>

namespace chaintube::editor {

namespace {

constexpr int kMaxRecentFiles = 8;
constexpr int kAutosaveIntervalMs = 30000;
enum TreeRole { KindRole = Qt::UserRole, IdRole, NodeRole };
enum TreeKind { SceneItem = 1, NodeItem, HoseItem, SocketItem };

QString sceneFileFilter()
{
    QStringList patterns;
    for (const std::string& extension : formats::supportedSceneExtensions())
        patterns << "*" + QString::fromStdString(extension);
    return QObject::tr("CAD and DCC scenes (%1)").arg(patterns.join(' '));
}

const formats::Rgba kHoseColours[] = {
    {0.08, 0.08, 0.08, 1.0}, {0.75, 0.1, 0.08, 1.0}, {0.1, 0.3, 0.75, 1.0},
    {0.9, 0.6, 0.05, 1.0},   {0.1, 0.55, 0.2, 1.0},  {0.7, 0.7, 0.72, 1.0},
};

} // namespace

formats::NamedRoots editorRoots(const QStringList& rootOptions, QString* error)
{
    formats::NamedRoots roots{{"scenes", CHAINTUBE_DEFAULT_SCENES_DIR}};
    QSettings settings;
    settings.beginGroup("roots");
    for (const QString& name : settings.childKeys())
        roots[name.toStdString()] = settings.value(name).toString().toStdString();
    settings.endGroup();
    for (const QString& option : rootOptions) {
        const int equals = option.indexOf('=');
        if (equals < 2) {
            if (error) *error = QObject::tr("--root expects NAME=DIR, got '%1'").arg(option);
            continue;
        }
        roots[option.left(equals).toStdString()] = option.mid(equals + 1).toStdString();
    }
    return roots;
}

bool MainWindow::recoverUntitled()
{
    return offerRecovery(QString(), autosavePath());
}

MainWindow::MainWindow(formats::NamedRoots roots, QWidget* parent)
    : QMainWindow(parent), m_document(std::make_unique<Document>(std::move(roots)))
{
    setObjectName("mainWindow");
    ask = [this](const QString& title, const QString& text, QMessageBox::StandardButtons buttons) {
        return QMessageBox::question(this, title, text, buttons);
    };
    showError = [this](const QString& title, const QString& text) {
        QMessageBox::warning(this, title, text);
    };
    m_viewport = new Viewport(*m_document, this);
    m_viewport->setObjectName("viewport");
    setCentralWidget(m_viewport);
    createDocks();
    createActions();
    statusBar()->showMessage(tr("Ready"));
    connect(m_document.get(), &Document::changed, this, &MainWindow::onDocumentChanged);
    connect(m_viewport, &Viewport::statusMessage, this,
            [this](const QString& message) { statusBar()->showMessage(message, 8000); });
    connect(m_viewport, &Viewport::routeFinished, this, &MainWindow::onRouteFinished);
    connect(&m_autosaveTimer, &QTimer::timeout, this, [this] { autosaveNow(); });
    m_autosaveTimer.start(kAutosaveIntervalMs);
    // Live gravity: runs only while a hose with gravity on is settling.
    m_gravityTimer.setInterval(kGravityIntervalMs);
    connect(&m_gravityTimer, &QTimer::timeout, this, [this] {
        m_document->advanceGravity(1e-9 * static_cast<double>(m_gravityClock.nsecsElapsed()));
        m_gravityClock.restart();
        if (!m_document->gravityActive()) {
            m_gravityTimer.stop();
            const auto unsettled = m_document->gravityUnsettledHoses();
            if (!unsettled.empty())
                statusBar()->showMessage(
                    tr("Gravity: hose '%1' was still moving after %2 steps and is left as it is")
                        .arg(QString::fromStdString(unsettled.front()))
                        .arg(Document::kGravityStepBudget),
                    8000);
        }
    });
    connect(m_document.get(), &Document::gravityStateChanged, this, [this] {
        if (m_document->gravityActive() && !m_gravityTimer.isActive()) {
            m_gravityTimer.start();
            m_gravityClock.start();
        }
    });

    QSettings settings;
    restoreGeometry(settings.value("window/geometry").toByteArray());
    restoreState(settings.value("window/state").toByteArray());
    if (settings.contains("view/wireframe")) {
        // (setChecked does not trigger the action: the viewport is told directly.)
        const bool wireframe = settings.value("view/wireframe").toBool();
        action("actionWireframe")->setChecked(wireframe);
        m_viewport->setWireframe(wireframe);
    }
    if (!settings.contains("window/geometry")) resize(1280, 800);
    rebuildSceneTree();
    updateTitle();
}

MainWindow::~MainWindow()
{
    // The viewport and panels listen to the document: delete them first.
    delete m_exportDialog;
    m_exportDialog = nullptr;
    delete m_viewport;
    m_viewport = nullptr;
    const auto docks = findChildren<QDockWidget*>();
    for (QDockWidget* dock : docks)
        delete dock;
    m_document->disconnect(this);
}

QAction* MainWindow::action(const QString& objectName) const
{
    return findChild<QAction*>(objectName);
}

void MainWindow::createDocks()
{
    m_sceneTree = new QTreeWidget;
    m_sceneTree->setObjectName("sceneTree");
    m_sceneTree->setMinimumWidth(240);
    m_sceneTree->setHeaderLabels({tr("Name"), tr("Kind")});
    m_sceneTree->header()->setStretchLastSection(false);
    m_sceneTree->header()->setSectionResizeMode(0, QHeaderView::Stretch);
    auto* treeDock = new QDockWidget(tr("Scene"), this);
    treeDock->setObjectName("sceneDock");
    treeDock->setWidget(m_sceneTree);
    addDockWidget(Qt::LeftDockWidgetArea, treeDock);
    const auto selectTreeItem = [this](QTreeWidgetItem* item) {
        if (m_syncingTree || !item) return;
        Selection selection = m_document->selection();
        const int kind = item->data(0, KindRole).toInt();
        const std::string id = item->data(0, IdRole).toString().toStdString();
        if (kind != SocketItem) selection.socketId.clear();
        if (kind == NodeItem) {
            selection.sceneId = id;
            selection.node = item->data(0, NodeRole).toInt();
        } else if (kind == HoseItem) {
            if (selection.hoseId != id)
                selection.rangeFirst = selection.rangeLast = selection.routePoint = -1;
            selection.hoseId = id;
        } else if (kind == SocketItem) {
            selection = Selection{};
            selection.socketId = id;
        } else {
            return;
        }
        m_document->setSelection(selection);
    };
    connect(m_sceneTree, &QTreeWidget::currentItemChanged, this, selectTreeItem);
    // A click on the row that is still current (the selection was cleared elsewhere) selects
    // it again: Qt reports no change of the current item then.
    connect(m_sceneTree, &QTreeWidget::itemClicked, this, selectTreeItem);

    m_properties = new PropertiesPanel(*m_document);
    connect(m_properties, &PropertiesPanel::statusMessage, this,
            [this](const QString& message) { statusBar()->showMessage(message, 10000); });
    auto* scroll = new QScrollArea;
    scroll->setWidget(m_properties);
    scroll->setWidgetResizable(true);
    scroll->setMinimumWidth(470);
    scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    // The fixing controls sit above the scrolling panel: they stay where they are while the
    // author scrolls to the part's fields and back.
    auto* propertiesPane = new QWidget;
    auto* propertiesLayout = new QVBoxLayout(propertiesPane);
    propertiesLayout->setContentsMargins(0, 0, 0, 0);
    propertiesLayout->addWidget(m_properties->fixControls());
    propertiesLayout->addWidget(scroll, 1);
    auto* propertiesDock = new QDockWidget(tr("Properties"), this);
    propertiesDock->setObjectName("propertiesDock");
    propertiesDock->setWidget(propertiesPane);
    addDockWidget(Qt::RightDockWidgetArea, propertiesDock);

    m_problems = new ProblemsPanel(*m_document);
    connect(m_problems, &ProblemsPanel::locateSceneRequested, this,
            [this](const std::string& sceneId) { locateScene(sceneId); });
    auto* problemsDock = new QDockWidget(tr("Problems"), this);
    problemsDock->setObjectName("problemsDock");
    problemsDock->setWidget(m_problems);
    addDockWidget(Qt::BottomDockWidgetArea, problemsDock);
    // Route points clicked on a surface keep the clearance the Problems panel checks.
    const auto followClearance = [this](double millimetres) {
        m_viewport->setRouteClearance(millimetres / 1000.0);
    };
    followClearance(m_problems->clearanceThreshold()->value());
    connect(m_problems->clearanceThreshold(), qOverload<double>(&QDoubleSpinBox::valueChanged),
            this, followClearance);

    m_motions = new MotionsPanel(*m_document);
    auto* motionsDock = new QDockWidget(tr("Motions"), this);
    motionsDock->setObjectName("motionsDock");
    motionsDock->setWidget(m_motions);
    addDockWidget(Qt::BottomDockWidgetArea, motionsDock);
    splitDockWidget(problemsDock, motionsDock, Qt::Horizontal);
    resizeDocks({problemsDock}, {300}, Qt::Vertical);
    // The sweep checks the clearance the Problems panel checks, and lists what it finds there.
    const auto sweepClearance = [this] {
        m_motions->setClearanceThreshold(m_problems->clearanceEnabled()->isChecked()
                                             ? m_problems->clearanceThreshold()->value() / 1000.0
                                             : 0.0);
    };
    sweepClearance();
    connect(m_problems->clearanceThreshold(), qOverload<double>(&QDoubleSpinBox::valueChanged),
            this, sweepClearance);
    connect(m_problems->clearanceEnabled(), &QCheckBox::toggled, this, sweepClearance);
    connect(m_motions, &MotionsPanel::sweepFinished, this, [this] {
        std::vector<Problem> problems;
        for (const SweepFinding& finding : m_motions->findings()) {
            Problem problem(finding.hoseId, finding.firstPoint, finding.lastPoint,
                            QString::fromStdString(finding.text));
            if (const formats::ImportedScene* scene = m_document->scene(finding.sceneId)) {
                problem.sceneId = finding.sceneId;
                problem.node = scene->findNode(finding.objectPath);
            }
            problem.motionValues = finding.values;
            problems.push_back(std::move(problem));
        }
        m_problems->setSweepProblems(std::move(problems));
    });

    m_history = new QUndoView(m_document->undoStack());
    m_history->setObjectName("history");
    auto* historyDock = new QDockWidget(tr("History"), this);
    historyDock->setObjectName("historyDock");
    historyDock->setWidget(m_history);
    addDockWidget(Qt::LeftDockWidgetArea, historyDock);
    resizeDocks({treeDock, historyDock}, {500, 200}, Qt::Vertical);
}

void MainWindow::createActions()
{
    auto make = [this](const QString& text, const char* name, const QKeySequence& shortcut,
                       auto slot) {
        auto* a = new QAction(text, this);
        a->setObjectName(name);
        if (!shortcut.isEmpty()) a->setShortcut(shortcut);
        connect(a, &QAction::triggered, this, slot);
        return a;
    };
    QMenu* file = menuBar()->addMenu(tr("&File"));
    file->addAction(make(tr("&New"), "actionNew", QKeySequence::New, [this] { newProject(); }));
    file->addAction(make(tr("&Open…"), "actionOpen", QKeySequence::Open, [this] {
        if (!maybeSave()) return;
        const QString path =
            askFile("openDialog", tr("Open project"), tr("ChainTube projects (*.ctproj)"), false);
        if (!path.isEmpty()) openFile(path);
    }));
    m_recentMenu = file->addMenu(tr("Open &Recent"));
    m_recentMenu->setObjectName("recentMenu");
    file->addAction(make(tr("&Save"), "actionSave", QKeySequence::Save, [this] { save(); }));
    // Explicit: QKeySequence::SaveAs is empty on some platforms (then no key and no menu hint).
    file->addAction(make(tr("Save &As…"), "actionSaveAs", QKeySequence(tr("Ctrl+Shift+S")), [this] {
        const QString path = askFile("saveAsDialog", tr("Save project as"),
                                     tr("ChainTube projects (*.ctproj)"), true);
        if (!path.isEmpty()) saveAs(path);
    }));
    file->addSeparator();
    file->addAction(
        make(tr("&Import Scene…"), "actionImportScene", QKeySequence(tr("Ctrl+I")), [this] {
            const QString path =
                askFile("importSceneDialog", tr("Import scene"), sceneFileFilter(), false);
            if (!path.isEmpty()) importSceneFile(path);
        }));
    QAction* locate =
        make(tr("&Locate Missing Scene…"), "actionLocateScene", QKeySequence(), [this] {
            if (!m_document->missingScenes().empty())
                locateScene(m_document->missingScenes().begin()->first);
        });
    locate->setEnabled(false);
    file->addAction(locate);
    file->addAction(make(tr("&Export…"), "actionExport", QKeySequence(tr("Ctrl+E")), [this] {
        exportDialog().show();
        exportDialog().raise();
    }));
    file->addSeparator();
    file->addAction(make(tr("&Quit"), "actionQuit", QKeySequence::Quit, [this] { close(); }));

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    QAction* undo = m_document->undoStack()->createUndoAction(this, tr("&Undo"));
    undo->setObjectName("actionUndo");
    undo->setShortcut(QKeySequence::Undo);
    QAction* redo = m_document->undoStack()->createRedoAction(this, tr("&Redo"));
    redo->setObjectName("actionRedo");
    redo->setShortcuts({QKeySequence::Redo, QKeySequence(tr("Ctrl+Y"))});
    edit->addAction(undo);
    edit->addAction(redo);
    edit->addSeparator();
    edit->addAction(
        make(tr("&Delete"), "actionDelete", QKeySequence::Delete, [this] { deleteSelection(); }));

    QMenu* hose = menuBar()->addMenu(tr("&Hose"));
    QAction* newHose =
        make(tr("&New Hose (click route points)"), "actionNewHose", QKeySequence(tr("N")), [this] {
            m_viewport->setMode(Viewport::Mode::LayRoute);
            m_viewport->setFocus();
        });
    hose->addAction(newHose);
    // Return and Escape only while a route is being laid out: otherwise these window-wide
    // shortcuts would take Return from the properties panel's fields (a typed value would
    // never be committed).
    QAction* finishRoute =
        make(tr("&Finish Route"), "actionFinishRoute", QKeySequence(Qt::Key_Return),
             [this] { m_viewport->finishRoute(); });
    QAction* cancelRoute =
        make(tr("&Cancel Route"), "actionCancelRoute", QKeySequence(Qt::Key_Escape),
             [this] { m_viewport->cancelRoute(); });
    hose->addAction(finishRoute);
    hose->addAction(cancelRoute);
    const auto enableRouteActions = [this, finishRoute, cancelRoute] {
        const bool laying = m_viewport->mode() == Viewport::Mode::LayRoute;
        finishRoute->setEnabled(laying);
        cancelRoute->setEnabled(m_viewport->mode() != Viewport::Mode::Select);
    };
    connect(m_viewport, &Viewport::modeChanged, this, enableRouteActions);
    enableRouteActions();
    hose->addAction(make(tr("&Insert Route Point"), "actionInsertRoutePoint", QKeySequence(tr("I")),
                         [this] { insertRoutePoint(); }));
    hose->addAction(make(tr("Fix to &Part…"), "actionFix", QKeySequence(tr("Ctrl+F")), [this] {
        m_viewport->beginFixToPart();
        m_viewport->setFocus();
    }));
    action("actionFix")
        ->setStatusTip(tr("Fixes the selected hose points to the part you click next"));
    connect(m_properties, &PropertiesPanel::fixToPartRequested, action("actionFix"),
            &QAction::trigger);
    hose->addAction(make(tr("Add &Clip…"), "actionAddClip", QKeySequence(tr("Ctrl+K")), [this] {
        m_viewport->beginClipToPart();
        m_viewport->setFocus();
    }));
    action("actionAddClip")
        ->setStatusTip(tr("Adds a clip at the selected hose point on the part you click next: "
                          "the hose passes through it and slides through when the part moves"));
    hose->addAction(make(tr("Add &Socket"), "actionAddSocket", QKeySequence(tr("Ctrl+J")), [this] {
        m_viewport->beginPlaceSocket();
        m_viewport->setFocus();
    }));
    action("actionAddSocket")
        ->setStatusTip(tr("Adds a socket (a coupling a hose end plugs into) where you click on "
                          "a part next; its axis is the surface normal"));
    hose->addAction(make(tr("&Detach All"), "actionDetach", QKeySequence(tr("Ctrl+D")), [this] {
        const formats::HoseDefinition* definition =
            m_document->hoseDefinition(m_document->selection().hoseId);
        if (!definition || definition->attachments.empty()) return;
        m_document->undoStack()->beginMacro(tr("Detach hose"));
        for (int i = int(definition->attachments.size()) - 1; i >= 0; --i)
            m_document->undoStack()->push(makeDetach(*m_document, definition->id, i));
        m_document->undoStack()->endMacro();
    }));

    hose->addAction(make(tr("Fit &Length…"), "actionFitLength", QKeySequence(tr("Ctrl+L")), [this] {
        fitHoseLengthInteractively(*m_document, m_document->selection().hoseId, this, showError);
    }));
    action("actionFitLength")
        ->setStatusTip(tr("The range of lengths valid over the motions, and one chosen in it"));

    QMenu* view = menuBar()->addMenu(tr("&View"));
    view->addAction(make(tr("&Frame Selection"), "actionFrameSelection", QKeySequence(tr("F")),
                         [this] { m_viewport->frameSelection(); }));
    view->addAction(make(tr("Frame &All"), "actionFrameAll", QKeySequence(Qt::Key_Home),
                         [this] { m_viewport->frameAll(); }));
    QAction* wireframe = make(tr("&Wireframe"), "actionWireframe", QKeySequence(tr("W")),
                              [this](bool on) { m_viewport->setWireframe(on); });
    wireframe->setCheckable(true);
    view->addAction(wireframe);
    view->addSeparator();
    for (QDockWidget* dock : findChildren<QDockWidget*>())
        view->addAction(dock->toggleViewAction());

    auto* toolbar = addToolBar(tr("Main"));
    toolbar->setObjectName("mainToolbar");
    for (const char* name : {"actionNew", "actionOpen", "actionSave", "actionImportScene",
                             "actionExport", "actionNewHose", "actionFix", "actionAddSocket",
                             "actionFrameSelection", "actionWireframe"})
        toolbar->addAction(action(name));
    // Every tooltip names its shortcut: "Fix to Part… (Ctrl+F)".
    for (QAction* a : findChildren<QAction*>()) {
        if (a->shortcut().isEmpty() || a->text().isEmpty()) continue;
        QString text = a->text();
        text.remove('&');
        a->setToolTip(tr("%1 (%2)").arg(text, a->shortcut().toString(QKeySequence::NativeText)));
    }
    rebuildRecentMenu();
}

ExportDialog& MainWindow::exportDialog()
{
    if (!m_exportDialog) m_exportDialog = new ExportDialog(*m_document, this);
    return *m_exportDialog;
}

void MainWindow::onDocumentChanged(const ChangeEvent& event)
{
    using Kind = ChangeEvent::Kind;
    switch (event.kind) {
    case Kind::ProjectReplaced:
    case Kind::ScenesChanged:
    case Kind::HoseAdded:
    case Kind::HoseRemoved:
    case Kind::SocketsChanged:
        rebuildSceneTree();
        if (QAction* locate = action("actionLocateScene"))
            locate->setEnabled(!m_document->missingScenes().empty());
        if (event.kind == Kind::ProjectReplaced) {
            delete m_exportDialog; // its defaults come from the project
            m_exportDialog = nullptr;
        }
        break;
    case Kind::HoseChanged:
        if (QTreeWidgetItem* root = m_sceneTree->topLevelItem(0))
            for (int i = 0; i < root->childCount(); ++i)
                if (root->child(i)->data(0, IdRole).toString().toStdString() == event.hoseId)
                    if (const auto* d = m_document->hoseDefinition(event.hoseId))
                        root->child(i)->setText(0, QString::fromStdString(d->name));
        break;
    case Kind::SelectionChanged:
        syncTreeSelection();
        break;
    case Kind::PoseChanged:
        reportHosesThatCannotFollow();
        break;
    case Kind::FileStateChanged:
        updateTitle();
        break;
    default:
        break;
    }
}

void MainWindow::reportHosesThatCannotFollow()
{
    // What the part move did to each hose (Document::lastUpdate): one that cannot reach its
    // part any more, or is kinked, says so at once in the status bar (the Problems panel and
    // the viewport show the details).
    QStringList short_, kinked;
    for (const formats::HoseDefinition& definition : m_document->project().hoses) {
        const UpdateResult result = m_document->lastUpdate(definition.id);
        const HoseMetrics* metrics = m_document->hoseMetrics(definition.id);
        if (!metrics || result.status == Status::Ok) continue;
        const QString name =
            QString::fromStdString(definition.name.empty() ? definition.id : definition.name);
        double gap = 0.0;
        for (const HoseMetrics::UnmetAttachment& unmet : metrics->unmetAttachments)
            gap = std::max(gap, unmet.gap);
        if (gap > 0.0)
            short_ << tr("%1 needs %2 mm more hose").arg(name).arg(gap * 1000.0, 0, 'f', 0);
        else if (!metrics->bendBelowMinimum.empty() || metrics->angleViolation > 1e-6)
            kinked << tr("%1 is kinked").arg(name);
        else if (metrics->overstretched())
            short_ << tr("%1 is overstretched").arg(name);
    }
    if (!short_.isEmpty() || !kinked.isEmpty())
        statusBar()->showMessage((short_ + kinked).join(tr("; ")), 8000);
}

void MainWindow::rebuildSceneTree()
{
    m_syncingTree = true;
    m_sceneTree->clear();
    auto* hoses = new QTreeWidgetItem(m_sceneTree, {tr("Hoses"), QString()});
    for (const formats::HoseDefinition& definition : m_document->project().hoses) {
        auto* item = new QTreeWidgetItem(
            hoses,
            {QString::fromStdString(definition.name.empty() ? definition.id : definition.name),
             tr("hose")});
        item->setData(0, KindRole, HoseItem);
        item->setData(0, IdRole, QString::fromStdString(definition.id));
    }
    hoses->setExpanded(true);
    for (const formats::SceneReference& reference : m_document->project().scenes) {
        const formats::ImportedScene* scene = m_document->scene(reference.id);
        auto* sceneItem = new QTreeWidgetItem(
            m_sceneTree, {QString::fromStdString(reference.id),
                          scene ? QString::fromStdString(scene->format) : tr("missing")});
        sceneItem->setData(0, KindRole, SceneItem);
        sceneItem->setToolTip(0, QString::fromStdString(reference.path));
        if (!scene) continue;
        std::vector<QTreeWidgetItem*> items(scene->nodes.size(), nullptr);
        for (size_t n = 0; n < scene->nodes.size(); ++n) {
            const formats::SceneNode& node = scene->nodes[n];
            QTreeWidgetItem* parent = node.parent >= 0 ? items[size_t(node.parent)] : sceneItem;
            auto* item =
                new QTreeWidgetItem(parent, {QString::fromStdString(node.name),
                                             node.meshes.empty() ? tr("group") : tr("part")});
            item->setData(0, KindRole, NodeItem);
            item->setData(0, IdRole, QString::fromStdString(reference.id));
            item->setData(0, NodeRole, int(n));
            item->setToolTip(0, QString::fromStdString(node.path));
            items[n] = item;
        }
        sceneItem->setExpanded(true);
        if (!items.empty()) items[0]->setExpanded(true);
    }
    if (!m_document->project().sockets.empty()) {
        auto* sockets = new QTreeWidgetItem(m_sceneTree, {tr("Sockets"), QString()});
        for (const formats::Socket& socket : m_document->project().sockets) {
            auto* item = new QTreeWidgetItem(
                sockets, {QString::fromStdString(socket.id),
                          tr("socket (%1)").arg(QString::fromStdString(socket.tag))});
            item->setData(0, KindRole, SocketItem);
            item->setData(0, IdRole, QString::fromStdString(socket.id));
            item->setToolTip(0, QString::fromStdString(socket.node));
        }
        sockets->setExpanded(true);
    }
    m_syncingTree = false;
    syncTreeSelection();
}

void MainWindow::syncTreeSelection()
{
    const Selection& selection = m_document->selection();
    m_syncingTree = true;
    QTreeWidgetItem* wanted = nullptr;
    for (QTreeWidgetItemIterator it(m_sceneTree); *it; ++it) {
        const int kind = (*it)->data(0, KindRole).toInt();
        const std::string id = (*it)->data(0, IdRole).toString().toStdString();
        if (kind == HoseItem && id == selection.hoseId) wanted = *it;
        if (kind == SocketItem && id == selection.socketId) wanted = *it;
        if (kind == NodeItem && id == selection.sceneId &&
            (*it)->data(0, NodeRole).toInt() == selection.node && selection.hoseId.empty())
            wanted = *it;
    }
    if (wanted) {
        m_sceneTree->setCurrentItem(wanted);
        m_sceneTree->scrollToItem(wanted);
    } else {
        // Nothing selected: no row stays highlighted or current.
        m_sceneTree->setCurrentItem(nullptr);
        m_sceneTree->clearSelection();
    }
    m_syncingTree = false;
}

void MainWindow::updateTitle()
{
    const QString name =
        m_document->fileName().empty()
            ? tr("Untitled")
            : QFileInfo(QString::fromStdString(m_document->fileName().string())).fileName();
    setWindowTitle(tr("%1[*] — ChainTube Studio").arg(name));
    setWindowModified(m_document->isModified());
}

bool MainWindow::maybeSave()
{
    if (!m_document->isModified()) return true;
    const auto answer =
        ask(tr("Unsaved changes"), tr("The project has unsaved changes. Save them?"),
            QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (answer == QMessageBox::Cancel) return false;
    if (answer == QMessageBox::Save) {
        if (m_document->fileName().empty()) {
            const QString path = askFile("saveAsDialog", tr("Save project as"),
                                         tr("ChainTube projects (*.ctproj)"), true);
            return !path.isEmpty() && saveAs(path);
        }
        return save();
    }
    removeAutosave(); // discarded on purpose: nothing to recover
    return true;
}

QString MainWindow::autosavePath() const
{
    if (!m_document->fileName().empty())
        return QString::fromStdString(m_document->fileName().string()) + ".autosave";
    const QString folder = QStandardPaths::writableLocation(QStandardPaths::AppLocalDataLocation);
    QDir().mkpath(folder);
    return folder + "/untitled.ctproj.autosave";
}

QString MainWindow::autosaveNow()
{
    if (!m_document->isModified()) return QString();
    const QString path = autosavePath();
    try {
        formats::writeFileAtomically(path.toStdString(),
                                     formats::serialiseProject(m_document->project()));
        statusBar()->showMessage(tr("Autosaved to %1").arg(path), 3000);
        return path;
    } catch (const std::exception& error) {
        statusBar()->showMessage(tr("Autosave failed: %1").arg(error.what()), 8000);
        return QString();
    }
}

void MainWindow::removeAutosave()
{
    QFile::remove(autosavePath());
}

bool MainWindow::offerRecovery(const QString& projectPath, const QString& autosave)
{
    const QFileInfo saved(projectPath), recovered(autosave);
    if (!recovered.exists() || (saved.exists() && recovered.lastModified() < saved.lastModified()))
        return false;
    const auto answer =
        ask(tr("Recover unsaved changes?"),
            tr("ChainTube Studio found unsaved changes of %1 from %2 (it was "
               "probably not closed normally). Recover them?")
                .arg(saved.fileName().isEmpty() ? tr("an untitled project") : saved.fileName(),
                     recovered.lastModified().toString()),
            QMessageBox::Yes | QMessageBox::No);
    if (answer != QMessageBox::Yes) {
        QFile::remove(autosave);
        return false;
    }
    QFile file(autosave);
    if (!file.open(QIODevice::ReadOnly)) return false;
    const std::string text = file.readAll().toStdString();
    LoadedProject loaded;
    QString error;
    const std::filesystem::path target =
        projectPath.isEmpty() ? std::filesystem::path(autosave.toStdString()).replace_extension()
                              : std::filesystem::path(projectPath.toStdString());
    const formats::NamedRoots roots = m_document->roots();
    if (!runWithProgress(
            this, tr("Recovering…"),
            [&](const std::function<bool(double)>& progress) {
                loaded = readProject(target, roots, progress, text);
            },
            &error)) {
        showError(tr("Recovery failed"), error);
        return false;
    }
    if (projectPath.isEmpty()) loaded.file.clear();
    m_document->adopt(std::move(loaded));
    m_document->setForcedModified(true);
    statusBar()->showMessage(tr("Recovered the autosaved state; save to keep it"), 8000);
    return true;
}

bool MainWindow::openFile(const QString& path)
{
    if (!maybeSave()) return false;
    const QString absolute = QFileInfo(path).absoluteFilePath();
    if (offerRecovery(absolute, absolute + ".autosave")) {
        addRecentFile(absolute);
        return true;
    }
    LoadedProject loaded;
    QString error;
    bool cancelled = false;
    if (!resolveNamedRoots(absolute))
        statusBar()->showMessage(tr("A scene folder is still unknown"), 8000);
    const formats::NamedRoots roots = m_document->roots();
    if (!runWithProgress(
            this, tr("Opening %1…").arg(QFileInfo(path).fileName()),
            [&](const std::function<bool(double)>& progress) {
                loaded = readProject(absolute.toStdString(), roots, progress);
            },
            &error, &cancelled)) {
        if (!cancelled) showError(tr("Cannot open project"), error);
        return false;
    }
    m_document->adopt(std::move(loaded));
    addRecentFile(absolute);
    if (m_document->missingScenes().empty())
        statusBar()->showMessage(tr("Opened %1").arg(absolute), 5000);
    else
        statusBar()->showMessage(
            tr("Opened %1; %n scene(s) missing: see Problems, or File ▸ Locate Missing Scene…",
               nullptr, int(m_document->missingScenes().size()))
                .arg(absolute),
            15000);
    return true;
}

bool MainWindow::resolveNamedRoots(const QString& projectPath)
{
    const std::filesystem::path file = projectPath.toStdString();
    formats::Project project;
    formats::NamedRoots roots = m_document->roots();
    try {
        formats::ProjectLoadOptions options;
        options.roots = roots;
        project = formats::loadProject(file, options);
    } catch (const std::exception&) {
        return true; // opening reports what is wrong with the file
    }
    bool answered = true;
    for (const formats::SceneReference& scene : project.scenes) {
        if (formats::classifyProjectPath(scene.path) != formats::PathKind::NamedRoot) continue;
        const std::string name = scene.path.substr(0, scene.path.find(':'));
        const auto found = [&] {
            std::error_code error;
            try {
                return std::filesystem::exists(formats::resolveScenePath(scene, file, roots),
                                               error);
            } catch (const std::exception&) {
                return false; // unknown root
            }
        };
        while (!found()) {
            const QString folder =
                askRootFolder(QString::fromStdString(name), QString::fromStdString(scene.path));
            if (folder.isEmpty()) {
                answered = false;
                break;
            }
            roots[name] = folder.toStdString();
            if (found()) {
                QSettings().setValue("roots/" + QString::fromStdString(name), folder);
                statusBar()->showMessage(tr("Scene folder '%1' is %2 (remembered)")
                                             .arg(QString::fromStdString(name), folder),
                                         8000);
            }
        }
    }
    m_document->setRoots(roots);
    return answered;
}

bool MainWindow::locateScene(const std::string& sceneId, QString file)
{
    const formats::SceneReference* reference = m_document->project().findScene(sceneId);
    if (!reference) return false;
    if (file.isEmpty())
        file = askFile(
            "locateSceneDialog",
            tr("Where is scene '%1'? (was %2)")
                .arg(QString::fromStdString(sceneId), QString::fromStdString(reference->path)),
            sceneFileFilter(), false);
    if (file.isEmpty()) {
        statusBar()->showMessage(
            tr("Scene '%1' is still missing").arg(QString::fromStdString(sceneId)), 8000);
        return false;
    }
    const std::filesystem::path chosen = QFileInfo(file).absoluteFilePath().toStdString();
    // Read as the project would read it: its import settings and placement, from the path it
    // will write.
    formats::Project one = m_document->project();
    one.scenes = {*reference};
    one.scenes[0].path = formats::projectPathFor(chosen,
                                                 m_document->fileName().empty()
                                                     ? std::filesystem::path()
                                                     : m_document->fileName().parent_path(),
                                                 m_document->roots());
    const std::filesystem::path projectFile = m_document->fileName().empty()
                                                  ? std::filesystem::current_path() / "untitled"
                                                  : m_document->fileName();
    const formats::NamedRoots roots = m_document->roots();
    formats::ImportedScenes imported;
    QString error;
    bool cancelled = false;
    if (!runWithProgress(
            this, tr("Reading %1…").arg(QFileInfo(file).fileName()),
            [&](const std::function<bool(double)>& progress) {
                imported = formats::importProjectScenes(one, projectFile, roots, progress);
            },
            &error, &cancelled)) {
        if (!cancelled) showError(tr("Cannot read the scene"), error);
        statusBar()->showMessage(
            tr("Scene '%1' is still missing").arg(QString::fromStdString(sceneId)), 8000);
        return false;
    }
    m_document->undoStack()->push(new RelinkSceneCommand(*m_document, sceneId, one.scenes[0].path,
                                                         std::move(imported.at(sceneId))));
    statusBar()->showMessage(
        tr("Scene '%1' is now %2")
            .arg(QString::fromStdString(sceneId), QString::fromStdString(one.scenes[0].path)),
        8000);
    return true;
}

QString MainWindow::dialogFolder() const
{
    if (!m_document->fileName().empty())
        return QString::fromStdString(m_document->fileName().parent_path().string());
    const QString last = QSettings().value("dialogs/lastFolder").toString();
    return !last.isEmpty() && QFileInfo(last).isDir() ? last : QDir::currentPath();
}

QString MainWindow::askFile(const QString& name, const QString& title, const QString& filter,
                            bool save)
{
    QFileDialog dialog(this, title, dialogFolder(), filter);
    dialog.setObjectName(name);
    // Qt's own dialog: the same on every desktop, and tests can drive it.
    dialog.setOption(QFileDialog::DontUseNativeDialog);
    if (save) {
        dialog.setAcceptMode(QFileDialog::AcceptSave);
        dialog.setFileMode(QFileDialog::AnyFile);
        dialog.setDefaultSuffix("ctproj");
        if (!m_document->fileName().empty())
            dialog.selectFile(QString::fromStdString(m_document->fileName().filename().string()));
    } else {
        dialog.setFileMode(QFileDialog::ExistingFile);
    }
    if (dialog.exec() != QDialog::Accepted || dialog.selectedFiles().isEmpty()) return QString();
    const QString chosen = dialog.selectedFiles().first();
    QSettings().setValue("dialogs/lastFolder", QFileInfo(chosen).absolutePath());
    return chosen;
}

QString MainWindow::askRootFolder(const QString& rootName, const QString& scenePath)
{
    QFileDialog dialog(this,
                       tr("Where is the scene folder '%1'? (for %2)").arg(rootName, scenePath));
    dialog.setObjectName("rootFolderDialog");
    dialog.setFileMode(QFileDialog::Directory);
    dialog.setOption(QFileDialog::ShowDirsOnly);
    // Qt's own dialog: the same on every desktop, and tests can drive it.
    dialog.setOption(QFileDialog::DontUseNativeDialog);
    dialog.setLabelText(QFileDialog::Accept, tr("Use this folder"));
    if (dialog.exec() != QDialog::Accepted || dialog.selectedFiles().isEmpty()) return QString();
    return dialog.selectedFiles().first();
}

bool MainWindow::save()
{
    if (m_document->fileName().empty()) {
        const QString path = askFile("saveAsDialog", tr("Save project as"),
                                     tr("ChainTube projects (*.ctproj)"), true);
        return !path.isEmpty() && saveAs(path);
    }
    return saveAs(QString::fromStdString(m_document->fileName().string()));
}

bool MainWindow::saveAs(const QString& path)
{
    const QString oldAutosave = autosavePath();
    try {
        m_document->save(QFileInfo(path).absoluteFilePath().toStdString());
    } catch (const std::exception& error) {
        showError(tr("Cannot save"), QString::fromStdString(error.what()));
        return false;
    }
    QFile::remove(oldAutosave);
    removeAutosave();
    addRecentFile(QFileInfo(path).absoluteFilePath());
    statusBar()->showMessage(tr("Saved %1").arg(path), 5000);
    return true;
}

void MainWindow::newProject()
{
    if (!maybeSave()) return;
    m_document->reset();
}

Vec3 MainWindow::placementOf(const formats::ImportedScene& scene, int placement) const
{
    const auto [low, high] = sceneBounds(scene);
    if (!(low.array() <= high.array()).all() || placement == int(ImportDialog::Placement::AsInFile))
        return Vec3::Zero();
    const Vec3 centre = 0.5 * (low + high);
    if (placement == int(ImportDialog::Placement::AtOrigin))
        return Vec3(-centre.x(), -low.y(), -centre.z());
    // Beside: right of everything the project holds (its scenes as placed, its hoses), on
    // its floor, centred on it in depth, a quarter of the new scene's width apart.
    Vec3 haveLow = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 haveHigh = -haveLow;
    for (const auto& [id, other] : m_document->scenes()) {
        const auto [otherLow, otherHigh] = sceneBounds(other);
        if ((otherLow.array() <= otherHigh.array()).all()) {
            haveLow = haveLow.cwiseMin(otherLow);
            haveHigh = haveHigh.cwiseMax(otherHigh);
        }
    }
    for (const formats::HoseDefinition& definition : m_document->project().hoses)
        if (const Hose* hose = m_document->hose(definition.id))
            for (const Vec3& p : hose->points()) {
                haveLow = haveLow.cwiseMin(p);
                haveHigh = haveHigh.cwiseMax(p);
            }
    if (!(haveLow.array() <= haveHigh.array()).all())
        return Vec3(-centre.x(), -low.y(), -centre.z());
    const double gap = std::max(0.05, 0.25 * (high.x() - low.x()));
    return Vec3(haveHigh.x() + gap - low.x(), haveLow.y() - low.y(),
                0.5 * (haveLow.z() + haveHigh.z()) - centre.z());
}

bool MainWindow::importSceneFile(const QString& path)
{
    const std::filesystem::path file = QFileInfo(path).absoluteFilePath().toStdString();
    formats::ImportedScene scene;
    const auto read = [&](const formats::SceneImportSettings& settings) {
        QString error;
        bool cancelled = false;
        if (runWithProgress(
                this, tr("Importing %1…").arg(QFileInfo(path).fileName()),
                [&](const std::function<bool(double)>& progress) {
                    formats::ImportOptions options;
                    options.metresPerUnit = settings.metresPerUnit;
                    options.upAxis = settings.upAxis;
                    options.progress = progress;
                    scene = formats::importScene(file, options);
                },
                &error, &cancelled))
            return true;
        if (cancelled)
            statusBar()->showMessage(tr("Import cancelled"), 5000);
        else
            showError(tr("Cannot import scene"), error);
        return false;
    };
    formats::SceneReference reference;
    if (!read(reference.import)) return false;
    // What the reader assumed (units, up axis) and where the scene goes: shown, changeable.
    const bool haveContent = !m_document->scenes().empty() || m_document->hoseCount() > 0;
    ImportDialog choice(scene, haveContent, this);
    if (choice.exec() != QDialog::Accepted) {
        statusBar()->showMessage(tr("Import cancelled"), 5000);
        return false;
    }
    reference.import.metresPerUnit = choice.metresPerUnit();
    reference.import.upAxis = choice.upAxis();
    if ((reference.import.metresPerUnit || reference.import.upAxis) && !read(reference.import))
        return false;
    reference.import.placement = placementOf(scene, int(choice.placement()));
    formats::placeScene(scene, reference.import.placement);
    // A unique id from the file name.
    std::string base = file.stem().string();
    for (char& c : base)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '-';
    reference.id = base;
    for (int n = 2; m_document->project().findScene(reference.id); ++n)
        reference.id = base + "-" + std::to_string(n);
    // The path as a project would write it: relative inside the project's folder, "root:rest"
    // inside a named root, else absolute.
    reference.path = formats::projectPathFor(file,
                                             m_document->fileName().empty()
                                                 ? std::filesystem::path()
                                                 : m_document->fileName().parent_path(),
                                             m_document->roots());
    m_document->undoStack()->push(new AddSceneCommand(*m_document, reference, std::move(scene)));
    m_viewport->frameAll();
    statusBar()->showMessage(tr("Imported %1").arg(path), 5000);
    return true;
}

void MainWindow::addRecentFile(const QString& path)
{
    QSettings settings;
    QStringList files = settings.value("recentFiles").toStringList();
    files.removeAll(path);
    files.prepend(path);
    while (files.size() > kMaxRecentFiles)
        files.removeLast();
    settings.setValue("recentFiles", files);
    rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu()
{
    m_recentMenu->clear();
    const QStringList files = QSettings().value("recentFiles").toStringList();
    for (const QString& file : files) {
        QAction* a = m_recentMenu->addAction(QFileInfo(file).fileName());
        a->setToolTip(file);
        // Opening rebuilds this menu: not while the menu is still handling the click.
        connect(a, &QAction::triggered, this,
                [this, file] { QTimer::singleShot(0, this, [this, file] { openFile(file); }); });
    }
    m_recentMenu->setEnabled(!files.isEmpty());
}

void MainWindow::onRouteFinished(const std::vector<Vec3>& route, double outerDiameter)
{
    formats::HoseDefinition definition;
    definition.id = m_document->unusedHoseId();
    definition.name = "Hose " + definition.id.substr(definition.id.find('-') + 1);
    definition.route = route;
    definition.outerDiameter = outerDiameter;
    const double routeLength = polylineLength(route);
    definition.segmentCount = newHoseSegmentCount(routeLength, outerDiameter);
    // The project's first preset if its bend radius suits the diameter, else own values with
    // a bend radius that does (route_layout.h).
    const auto& presets = m_document->project().materialPresets;
    const NewHoseMaterial material =
        newHoseMaterial(presets.empty() ? Material() : presets.front().material, outerDiameter,
                        routeLength / definition.segmentCount);
    if (material.presetKept && !presets.empty())
        definition.material = formats::PresetName{presets.front().name};
    else
        definition.material = material.material;
    definition.colour = kHoseColours[size_t(m_document->hoseCount()) % std::size(kHoseColours)];
    // The hose laid between the clicked points keeps the clearance too: where it passes nearer
    // a part (a leg along an edge, an arc over a bracket), route points are added there.
    const formats::Project& project = m_document->project();
    const BendLimit& limit = material.material.bendLimit;
    const double bendRadius =
        limit.kind == BendLimit::Kind::MinBendRadius
            ? limit.value
            : bendRadiusOfTurn(routeLength / definition.segmentCount, limit.value);
    const ClearedRoute cleared = keepRouteClearOfSurfaces(
        route, routePointDistance(outerDiameter, m_viewport->routeClearance()), bendRadius,
        [&](const std::vector<Vec3>& candidate) {
            formats::HoseDefinition laid = definition;
            laid.route = candidate;
            try {
                laid.length = formats::routeRestLength(project, laid);
                return formats::buildHose(project, laid, m_document->scenes()).points();
            } catch (const std::exception&) {
                return std::vector<Vec3>{};
            }
        },
        m_viewport->nearestSurfaceQuery());
    definition.route = cleared.route;
    try {
        // As long as the route, from now on its own (route edits never change it).
        definition.length = formats::routeRestLength(project, definition);
    } catch (const std::exception&) {
        // validateHoseDefinition says why below
    }
    const std::string problem = m_document->validateHoseDefinition(definition);
    if (!problem.empty()) {
        showError(tr("Cannot lay out this hose"), QString::fromStdString(problem));
        return;
    }
    m_document->undoStack()->push(new AddHoseCommand(*m_document, definition));
    Selection selection = m_document->selection();
    selection.hoseId = definition.id;
    selection.rangeFirst = selection.rangeLast = selection.routePoint = -1;
    m_document->setSelection(selection);
    QString note;
    if (cleared.added > 0)
        note =
            cleared.added == 1
                ? tr(" (a route point added to keep it clear of the parts)")
                : tr(" (%1 route points added to keep it clear of the parts)").arg(cleared.added);
    if (!cleared.clear)
        note += tr("; it passes %1 mm from a part, nearer than the %2 mm clearance")
                    .arg((cleared.clearance - 0.5 * outerDiameter) * 1000.0, 0, 'f', 1)
                    .arg(m_viewport->routeClearance() * 1000.0, 0, 'f', 1);
    statusBar()->showMessage(tr("Added %1%2").arg(QString::fromStdString(definition.name), note),
                             8000);
}

void MainWindow::deleteSelection()
{
    Selection selection = m_document->selection();
    if (selection.hoseId.empty() && m_document->project().findSocket(selection.socketId)) {
        m_document->undoStack()->push(makeRemoveSocket(*m_document, selection.socketId));
        return;
    }
    const formats::HoseDefinition* definition = m_document->hoseDefinition(selection.hoseId);
    if (!definition) return;
    if (selection.routePoint >= 0 && selection.routePoint < int(definition->route.size())) {
        if (definition->route.size() <= 2) {
            statusBar()->showMessage(tr("A hose needs at least two route points"), 5000);
            return;
        }
        std::vector<Vec3> route = definition->route;
        route.erase(route.begin() + selection.routePoint);
        formats::HoseDefinition changed = *definition;
        changed.route = route;
        const std::string problem = m_document->validateHoseDefinition(changed);
        if (!problem.empty()) {
            statusBar()->showMessage(QString::fromStdString(problem), 8000);
            return;
        }
        m_document->undoStack()->push(
            makeSetRoute(*m_document, selection.hoseId, route, tr("Delete route point")));
        selection.routePoint = -1;
        m_document->setSelection(selection);
        return;
    }
    m_document->undoStack()->push(new RemoveHoseCommand(*m_document, selection.hoseId));
}

void MainWindow::insertRoutePoint()
{
    Selection selection = m_document->selection();
    const formats::HoseDefinition* definition = m_document->hoseDefinition(selection.hoseId);
    if (!definition) return;
    // After the selected route point (or before the last one): the middle of that leg.
    int after =
        selection.routePoint >= 0 ? selection.routePoint : int(definition->route.size()) - 2;
    after = std::clamp(after, 0, int(definition->route.size()) - 2);
    std::vector<Vec3> route = definition->route;
    route.insert(route.begin() + after + 1,
                 0.5 * (route[size_t(after)] + route[size_t(after) + 1]));
    m_document->undoStack()->push(
        makeSetRoute(*m_document, selection.hoseId, route, tr("Insert route point")));
    selection.routePoint = after + 1;
    m_document->setSelection(selection);
}

void MainWindow::closeEvent(QCloseEvent* event)
{
    if (!maybeSave()) {
        event->ignore();
        return;
    }
    QSettings settings;
    settings.setValue("window/geometry", saveGeometry());
    settings.setValue("window/state", saveState());
    settings.setValue("view/wireframe", action("actionWireframe")->isChecked());
    removeAutosave();
    event->accept();
}

} // namespace chaintube::editor
