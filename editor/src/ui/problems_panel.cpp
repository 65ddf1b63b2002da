#include "problems_panel.h"

#include <cmath>

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

} // namespace

std::vector<Problem> findProblems(const Document& document)
{
    std::vector<Problem> problems;
    for (const formats::HoseDefinition& definition : document.project().hoses) {
        const QString name = QString::fromStdString(definition.name.empty() ? definition.id
                                                                            : definition.name);
        const Hose* hose = document.hose(definition.id);
        if (!hose) {
            problems.push_back({definition.id, -1, -1,
                                QObject::tr("%1: cannot be built: %2")
                                    .arg(name, QString::fromStdString(
                                                   document.hoseBuildError(definition.id)))});
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
        if (metrics) {
            for (const auto& [first, last] : runs(metrics->bendBelowMinimum)) {
                const Material material = hose->material();
                problems.push_back(
                    {definition.id, first, last,
                     QObject::tr("%1: bend radius %2 mm below the minimum %3 mm at joints %4–%5")
                         .arg(name)
                         .arg(metrics->smallestBendRadius * 1000.0, 0, 'f', 1)
                         .arg(material.bendLimit.value * 1000.0, 0, 'f', 1)
                         .arg(first)
                         .arg(last)});
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

ProblemsPanel::ProblemsPanel(Document& document, QWidget* parent)
    : QListWidget(parent), m_document(document)
{
    setObjectName("problemsPanel");
    m_throttle.setSingleShot(true);
    m_throttle.setInterval(100);
    connect(&m_throttle, &QTimer::timeout, this, &ProblemsPanel::refreshNow);
    connect(&m_document, &Document::changed, this, [this](const ChangeEvent& event) {
        if (event.kind != ChangeEvent::Kind::SelectionChanged &&
            event.kind != ChangeEvent::Kind::FileStateChanged && !m_throttle.isActive())
            m_throttle.start();
    });
    connect(this, &QListWidget::itemClicked, this, [this](QListWidgetItem* item) {
        const int index = row(item);
        if (index < 0 || index >= int(m_problems.size()))
            return;
        const Problem& problem = m_problems[size_t(index)];
        Selection selection = m_document.selection();
        selection.hoseId = problem.hoseId;
        selection.rangeFirst = problem.firstPoint;
        selection.rangeLast = problem.lastPoint;
        selection.routePoint = -1;
        m_document.setSelection(selection);
    });
    refreshNow();
}

void ProblemsPanel::refreshNow()
{
    m_problems = findProblems(m_document);
    clear();
    for (const Problem& problem : m_problems) {
        auto* item = new QListWidgetItem(problem.text, this);
        item->setForeground(QColor(255, 120, 100));
    }
    if (m_problems.empty())
        addItem(tr("No problems"));
}

} // namespace chaintube::editor
