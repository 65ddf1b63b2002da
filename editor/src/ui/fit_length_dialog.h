// ChainTube editor — "Fit length…": the range of lengths for which the selected hose stays valid
// over the project's motions (exporting::fitHoseLength, the function `chaintube check
// --fit-length` calls), and a length chosen in it, applied as one undo step.
#pragma once

#include "chaintube/editor/document.h"

#include <QDialog>
#include <chaintube/export/fit_length.h>
#include <optional>

class QDoubleSpinBox;
class QLabel;

namespace chaintube::editor {

/// Shows a fitted range and lets the user choose a length in it (metres, to the millimetre).
/// The default is the shortest length plus 5 % of it, or the middle of the range when that is
/// narrower: a little slack over the taut length.
class FitLengthDialog : public QDialog
{
    Q_OBJECT
public:
    FitLengthDialog(const QString& hoseLabel, const exporting::LengthFit& fit,
                    QWidget* parent = nullptr);
    double chosenLength() const;
    /// The default choice for a range (see the class comment).
    static double defaultLength(const exporting::LengthFit& fit);

private:
    QDoubleSpinBox* m_length;
};

/// Fits the length of hose `hoseId` of the document with a progress dialog (Cancel stops it),
/// shows the range in a FitLengthDialog and, when accepted, pushes one command that sets the
/// chosen length. Problems (not between fixed ends, no valid length, a failed fit) are shown
/// with `showError`. Returns true when a length was applied.
bool fitHoseLengthInteractively(
    Document& document, const std::string& hoseId, QWidget* parent,
    const std::function<void(const QString&, const QString&)>& showError);

} // namespace chaintube::editor
