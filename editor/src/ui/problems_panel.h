// ChainTube editor — the problems panel: hoses that cannot be built, overstretched segments,
// bends tighter than the material's minimum radius (or beyond its deflection angle), and ring
// self-intersection. The viewport tints the same regions red; clicking a problem selects the
// hose and the offending axis points.
#pragma once

#include "chaintube/editor/document.h"

#include <QListWidget>
#include <QTimer>

namespace chaintube::editor {

/// One problem, as listed.
struct Problem
{
    std::string hoseId;
    int firstPoint = -1; ///< offending axis points (−1: the whole hose)
    int lastPoint = -1;
    QString text;
};

/// All problems of a document, hose by hose (pure function; used by the panel and tests).
std::vector<Problem> findProblems(const Document& document);

class ProblemsPanel : public QListWidget
{
    Q_OBJECT
public:
    explicit ProblemsPanel(Document& document, QWidget* parent = nullptr);
    const std::vector<Problem>& problems() const { return m_problems; }
    /// Recomputes now (normally done at most every 100 ms after a change).
    void refreshNow();

private:
    Document& m_document;
    std::vector<Problem> m_problems;
    QTimer m_throttle;
};

} // namespace chaintube::editor
