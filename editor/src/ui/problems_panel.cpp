#include "problems_panel.h"

#include "chaintube/editor/commands.h"

#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QHBoxLayout>
#include <QResizeEvent>
#include <chaintube/export/clearance.h>
#include <chaintube/route.h>
#include <cmath>
#include <limits>

namespace chaintube::editor {

namespace {

/// Groups sorted indices into contiguous runs.
std::vector<std::pair<int, int>> runs(std::vector<int> indices)
{
    std::sort(indices.begin(), indices.end());
    std::vector<std::pair<int, int>> result;
    for (int index : indices) {
        if (!result.empty() && index <= result.back().second + 1)
            result.back().second = index;
        else
            result.push_back({index, index});
    }
    return result;
}

/// Bend radius at joint j of the hose's current shape (metres; as measure() computes it).
double jointBendRadius(const Hose& hose, int j)
{
    const Vec3 in = hose.point(j) - hose.point(j - 1);
    const Vec3 out = hose.point(j + 1) - hose.point(j);
    const double turn = std::atan2(in.cross(out).norm(), in.dot(out));
    return bendRadiusOfTurn(0.5 * (in.norm() + out.norm()), turn);
}

/// Where the clicks left a route corner too tight for its legs (no room for the bend radius),
/// a kink of the hose is theirs: " — route point N is too tight for its legs (an arc of R mm
/// fits)", naming the tightest such corner (1-based, as the route handles are counted), else
/// empty. Only for a clicked route, not one that is the hose's axis.
QString tightRoutePointNote(const Hose& hose, const formats::HoseDefinition& definition)
{
    const BendLimit& limit = hose.material().bendLimit;
    if (limit.kind != BendLimit::Kind::MinBendRadius || !(limit.value > 0.0)) return {};
    // A route that is the hose's own axis (a committed drag stores it so) has a corner at every
    // joint: its kinks are the shape's, not the clicks'.
    if (definition.route.size() == size_t(hose.pointCount())) return {};
    const TightCorner* tightest = nullptr;
    const std::vector<TightCorner> tight = tightCorners(definition.route, limit.value);
    for (const TightCorner& corner : tight)
        if (corner.reachedRadius < limit.value * (1.0 - 1e-3) && // not rounding
            (!tightest || corner.reachedRadius < tightest->reachedRadius))
            tightest = &corner;
    if (!tightest) return {};
    return QObject::tr(" — route point %1 is too tight for its legs (an arc of %2 mm fits)")
        .arg(tightest->routePoint + 1)
        .arg(tightest->reachedRadius * 1000.0, 0, 'f', 1);
}

} // namespace

std::vector<Problem> findProblems(const Document& document)
{
    std::vector<Problem> problems;
    for (const formats::SceneReference& reference : document.project().scenes) {
        const auto missing = document.missingScenes().find(reference.id);
        if (missing == document.missingScenes().end()) continue;
        Problem problem{{},
                        -1,
                        -1,
                        QObject::tr("Scene '%1' is missing: %2 — click here to locate it "
                                    "(File ▸ Locate Missing Scene…)")
                            .arg(QString::fromStdString(reference.id),
                                 QString::fromStdString(missing->second))};
        problem.missingScene = reference.id;
        problems.push_back(std::move(problem));
    }
    for (const formats::HoseDefinition& definition : document.project().hoses) {
        const QString name =
            QString::fromStdString(definition.name.empty() ? definition.id : definition.name);
        const Hose* hose = document.hose(definition.id);
        if (!hose) {
            problems.push_back(
                {definition.id, -1, -1,
                 QObject::tr("%1: cannot be built: %2")
                     .arg(name, QString::fromStdString(document.hoseBuildError(definition.id)))});
            continue;
        }
        const HoseMetrics* metrics = document.hoseMetrics(definition.id);
        // Overstretched (or compressed) segments, all of them, not only the worst.
        std::vector<int> stretched;
        double worst = 0.0;
        for (int s = 0; s < hose->segmentCount(); ++s) {
            const double length = (hose->point(s + 1) - hose->point(s)).norm();
            const double over = std::max(length - hose->maxLength(s), hose->minLength(s) - length);
            if (over > 1e-6 * hose->restLength(s)) {
                stretched.push_back(s);
                worst = std::max(worst, over / hose->restLength(s));
            }
        }
        for (const auto& [first, last] : runs(stretched))
            problems.push_back({definition.id, first, last + 1,
                                QObject::tr("%1: overstretched at segments %2–%3 (up to %4 % "
                                            "beyond the stretch band)")
                                    .arg(name)
                                    .arg(first)
                                    .arg(last)
                                    .arg(worst * 100.0, 0, 'f', 1)});
        // A collider it runs into and cannot be pushed out of within its lengths (a part
        // flagged or moved onto it): the hose keeps its shape and says how deep it is in.
        const UpdateResult lastUpdate = document.lastUpdate(definition.id);
        if (lastUpdate.status == Status::Infeasible && lastUpdate.penetration > 0.0)
            problems.push_back({definition.id, -1, -1,
                                QObject::tr("%1: runs %2 mm into a collider and cannot be pushed "
                                            "out within its length")
                                    .arg(name)
                                    .arg(lastUpdate.penetration * 1000.0, 0, 'f', 1)});
        if (metrics) {
            // Attachments the hose cannot reach (a part moved beyond it): the hose lies taut
            // towards them and says how much hose is missing.
            for (const HoseMetrics::UnmetAttachment& unmet : metrics->unmetAttachments) {
                const auto& built = hose->attachments();
                for (size_t a = 0; a < built.size() && a < definition.attachments.size(); ++a)
                    if (built[a].id == unmet.id)
                        problems.push_back(
                            {definition.id, built[a].first, built[a].last,
                             QObject::tr("%1: needs %2 mm more hose to reach %3 (points %4–%5)")
                                 .arg(name)
                                 .arg(unmet.gap * 1000.0, 0, 'f', 0)
                                 .arg(QString::fromStdString(definition.attachments[a].node))
                                 .arg(built[a].first)
                                 .arg(built[a].last)});
                // Clips come after the attachments (formats::buildHose).
                for (size_t c = 0; c < definition.clips.size(); ++c) {
                    const size_t a = definition.attachments.size() + c;
                    if (a < built.size() && built[a].id == unmet.id)
                        problems.push_back(
                            {definition.id, built[a].first, built[a].last,
                             QObject::tr("%1: cannot pass through the clip on %2: %3 mm off "
                                         "(no hose left to slide through it)")
                                 .arg(name)
                                 .arg(QString::fromStdString(definition.clips[c].node))
                                 .arg(unmet.gap * 1000.0, 0, 'f', 0)});
                }
            }
            for (const auto& [first, last] : runs(metrics->bendBelowMinimum)) {
                const Material material = hose->material();
                double smallest = std::numeric_limits<double>::max();
                for (int j = first; j <= last; ++j)
                    smallest = std::min(smallest, jointBendRadius(*hose, j));
                problems.push_back(
                    {definition.id, first, last,
                     QObject::tr("%1: kinked: bend radius %2 mm, below the minimum %3 mm, at "
                                 "joints %4–%5%6")
                         .arg(name)
                         .arg(smallest * 1000.0, 0, 'f', 1)
                         .arg(material.bendLimit.value * 1000.0, 0, 'f', 1)
                         .arg(first)
                         .arg(last)
                         .arg(tightRoutePointNote(*hose, definition))});
            }
            if (metrics->bendBelowMinimum.empty() && metrics->angleViolation > 1e-6)
                problems.push_back({definition.id, metrics->angleViolationJoint,
                                    metrics->angleViolationJoint,
                                    QObject::tr("%1: bends %2° beyond the deflection angle at "
                                                "joint %3")
                                        .arg(name)
                                        .arg(metrics->angleViolation * 180.0 / M_PI, 0, 'f', 1)
                                        .arg(metrics->angleViolationJoint)});
            for (const auto& [first, last] : runs(metrics->selfIntersectingSegments))
                problems.push_back({definition.id, first, last + 1,
                                    QObject::tr("%1: rings intersect on the inside of the bend "
                                                "at segments %2–%3")
                                        .arg(name)
                                        .arg(first)
                                        .arg(last)});
        }
    }
    return problems;
}

/// The scene objects as colliders, kept while the scenes and poses stay the same.
struct ProblemsPanel::ClearanceCache
{
    std::vector<std::pair<std::string, size_t>> scenes; ///< id, node count
    std::vector<formats::NodePose> poses;
    std::vector<exporting::SceneObject> objects;
    bool matches(const Document& document) const
    {
        std::vector<std::pair<std::string, size_t>> now;
        for (const auto& [id, scene] : document.scenes())
            now.emplace_back(id, scene.nodes.size());
        return now == scenes && document.project().poses == poses;
    }
};

ProblemsPanel::~ProblemsPanel() = default;

void ProblemsPanel::resizeEvent(QResizeEvent* event)
{
    QListWidget::resizeEvent(event);
    const QRect inside = contentsRect();
    m_clearanceBar->setGeometry(inside.left(), inside.top(), inside.width(),
                                m_clearanceBar->sizeHint().height());
}

ProblemsPanel::ProblemsPanel(Document& document, QWidget* parent)
    : QListWidget(parent), m_document(document)
{
    setObjectName("problemsPanel");
    // Clearance controls above the list: "[x] Clearance below [5.0 mm]".
    m_clearanceBar = new QWidget(this);
    auto* bar = new QHBoxLayout(m_clearanceBar);
    bar->setContentsMargins(4, 2, 4, 2);
    m_clearanceEnabled = new QCheckBox(tr("Clearance below"), m_clearanceBar);
    m_clearanceEnabled->setObjectName("clearanceEnabled");
    m_clearanceEnabled->setChecked(true);
    m_clearanceThreshold = new QDoubleSpinBox(m_clearanceBar);
    m_clearanceThreshold->setObjectName("clearanceThreshold");
    m_clearanceThreshold->setRange(0.0, 1000.0);
    m_clearanceThreshold->setDecimals(1);
    m_clearanceThreshold->setSuffix(tr(" mm"));
    m_clearanceThreshold->setValue(formats::kDefaultClearance * 1000.0);
    m_clearanceThreshold->setToolTip(
        tr("Hoses closer than this to a scene object are listed and "
           "marked in the viewport (nodes a hose is fixed to are skipped). The project's "
           "threshold: saved with it, and what `chaintube check` uses without options"));
    bar->addWidget(m_clearanceEnabled);
    bar->addWidget(m_clearanceThreshold);
    bar->addStretch(1);
    setViewportMargins(0, m_clearanceBar->sizeHint().height(), 0, 0);
    connect(m_clearanceEnabled, &QCheckBox::toggled, this, &ProblemsPanel::refreshNow);
    connect(m_clearanceThreshold, qOverload<double>(&QDoubleSpinBox::valueChanged), this,
            [this](double millimetres) {
                m_throttle.start();
                // The threshold is the project's ("checks"/"clearance"): saved with it, used
                // by `chaintube check` without options, one undo step per edit.
                if (m_syncingThreshold) return;
                formats::CheckSettings checks = m_document.project().checks;
                const double metres = millimetres / 1000.0;
                if (checks.clearance.value_or(formats::kDefaultClearance) == metres) return;
                checks.clearance = metres;
                m_document.undoStack()->push(makeSetCheckSettings(m_document, checks));
            });
    m_throttle.setSingleShot(true);
    m_throttle.setInterval(100);
    connect(&m_throttle, &QTimer::timeout, this, &ProblemsPanel::refreshNow);
    connect(&m_document, &Document::changed, this, [this](const ChangeEvent& event) {
        if (event.kind == ChangeEvent::Kind::ProjectReplaced ||
            event.kind == ChangeEvent::Kind::ProjectSettingsChanged)
            showProjectThreshold();
        if (event.kind != ChangeEvent::Kind::SelectionChanged &&
            event.kind != ChangeEvent::Kind::FileStateChanged && !m_throttle.isActive())
            m_throttle.start();
    });
    connect(this, &QListWidget::itemClicked, this, [this](QListWidgetItem* item) {
        const int index = row(item);
        if (index < 0 || index >= int(m_problems.size())) return;
        const Problem& problem = m_problems[size_t(index)];
        if (!problem.missingScene.empty()) {
            const std::string sceneId = problem.missingScene; // a refresh may follow
            emit locateSceneRequested(sceneId);
            return;
        }
        Selection selection = m_document.selection();
        selection.hoseId = problem.hoseId;
        selection.rangeFirst = problem.firstPoint;
        selection.rangeLast = problem.lastPoint;
        selection.routePoint = -1;
        if (!problem.sceneId.empty()) { // a clearance violation: select the object too
            selection.sceneId = problem.sceneId;
            selection.node = problem.node;
        }
        const std::vector<double> motionValues = problem.motionValues; // refreshes may follow
        m_document.setSelection(selection);
        if (!motionValues.empty()) m_document.setMotionPreview(motionValues);
    });
    showProjectThreshold();
    refreshNow();
}

void ProblemsPanel::showProjectThreshold()
{
    m_syncingThreshold = true;
    m_clearanceThreshold->setValue(
        m_document.project().checks.clearance.value_or(formats::kDefaultClearance) * 1000.0);
    m_syncingThreshold = false;
}

void ProblemsPanel::setSweepProblems(std::vector<Problem> problems)
{
    m_sweepProblems = std::move(problems);
    refreshNow();
}

void ProblemsPanel::refreshNow()
{
    m_problems = findProblems(m_document);
    std::vector<ClearanceMarker> markers;
    if (m_clearanceEnabled->isChecked()) {
        if (!m_clearanceCache || !m_clearanceCache->matches(m_document)) {
            auto cache = std::make_unique<ClearanceCache>();
            for (const auto& [id, scene] : m_document.scenes())
                cache->scenes.emplace_back(id, scene.nodes.size());
            cache->poses = m_document.project().poses;
            try {
                cache->objects = exporting::sceneObjects(m_document.project(), m_document.scenes());
            } catch (const std::exception&) {
                cache->objects.clear(); // a pose naming a missing node: reported elsewhere
            }
            m_clearanceCache = std::move(cache);
        }
        std::vector<const Hose*> hoses;
        for (const formats::HoseDefinition& definition : m_document.project().hoses)
            hoses.push_back(m_document.hose(definition.id));
        exporting::ClearanceOptions options;
        options.threshold = m_clearanceThreshold->value() / 1000.0;
        for (const exporting::ClearanceFinding& finding : exporting::clearanceViolations(
                 m_document.project(), hoses, m_clearanceCache->objects, options)) {
            const formats::HoseDefinition& definition =
                m_document.project().hoses[size_t(finding.hose)];
            const QString name =
                QString::fromStdString(definition.name.empty() ? definition.id : definition.name);
            // The distance is signed (negative: the hose surface is inside the object); a
            // person reads "2.5 mm into", not "-2.5 mm from", and never "-0.0 mm".
            const double millimetres = finding.distance * 1000.0;
            const QString where = QString::fromStdString(finding.objectPath);
            const QString how = std::abs(millimetres) < 0.05 ? tr("touches %1").arg(where)
                                : millimetres < 0.0
                                    ? tr("%1 mm into %2").arg(-millimetres, 0, 'f', 1).arg(where)
                                    : tr("%1 mm from %2").arg(millimetres, 0, 'f', 1).arg(where);
            Problem problem{definition.id, finding.axisPoint, finding.axisPoint,
                            tr("%1: %2 at axis point %3 (clearance %4 mm)")
                                .arg(name, how)
                                .arg(finding.axisPoint)
                                .arg(m_clearanceThreshold->value(), 0, 'f', 1)};
            problem.sceneId = finding.sceneId;
            problem.node = m_clearanceCache->objects[size_t(finding.object)].node;
            m_problems.push_back(std::move(problem));
            markers.push_back({definition.id, finding.axisPoint, finding.onHose, finding.onObject});
        }
    }
    m_document.setClearanceMarkers(std::move(markers));
    m_problems.insert(m_problems.end(), m_sweepProblems.begin(), m_sweepProblems.end());
    clear();
    for (const Problem& problem : m_problems) {
        auto* item = new QListWidgetItem(problem.text, this);
        item->setForeground(QColor(255, 120, 100));
        item->setToolTip(problem.text); // a long line is cut at the panel's edge
    }
    if (m_problems.empty()) addItem(tr("No problems"));
}

} // namespace chaintube::editor
