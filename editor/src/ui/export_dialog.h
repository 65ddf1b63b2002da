// ChainTube editor — the Export dialog: GLB or glTF + descriptor, with progress and a summary
// of what was written. It calls exportProjectForEditor(), i.e. the function the CLI calls.
#pragma once

#include "chaintube/editor/document.h"

#include <QDialog>

class QCheckBox;
class QComboBox;
class QLineEdit;
class QPlainTextEdit;
class QPushButton;

namespace chaintube::editor {

class ExportDialog : public QDialog
{
    Q_OBJECT
public:
    ExportDialog(Document& document, QWidget* parent = nullptr);

    void setOutputPath(const QString& path);
    /// Runs the export with the dialog's settings (with a progress dialog). Returns true on
    /// success; the summary (or the error) is then in summaryText().
    bool runExport();
    QString summaryText() const;

private:
    Document& m_document;
    QLineEdit* m_output;
    QComboBox* m_format;
    QCheckBox* m_includeScene;
    QCheckBox* m_descriptor;
    QPlainTextEdit* m_summary;
    QPushButton* m_exportButton;
};

} // namespace chaintube::editor
