#include "import_runner.h"

#include "chaintube/formats/errors.h"

#include <QApplication>
#include <QElapsedTimer>
#include <QProgressDialog>
#include <QThread>
#include <atomic>
#include <exception>
#include <thread>

namespace chaintube::editor {

bool runWithProgress(QWidget* parent, const QString& label,
                     const std::function<void(const std::function<bool(double)>&)>& work,
                     QString* error, bool* cancelled)
{
    std::atomic<int> permille{0};
    std::atomic<bool> cancelRequested{false};
    std::atomic<bool> done{false};
    std::exception_ptr failure;
    std::thread worker([&] {
        try {
            work([&](double fraction) {
                permille = int(std::clamp(fraction, 0.0, 1.0) * 1000.0);
                return !cancelRequested.load();
            });
        } catch (...) {
            failure = std::current_exception();
        }
        done = true;
    });
    QProgressDialog dialog(label, QObject::tr("Cancel"), 0, 1000, parent);
    dialog.setObjectName("progressDialog");
    dialog.setWindowModality(Qt::WindowModal);
    dialog.setMinimumDuration(300);
    QObject::connect(&dialog, &QProgressDialog::canceled, [&] { cancelRequested = true; });
    while (!done) {
        dialog.setValue(permille);
        QApplication::processEvents(QEventLoop::AllEvents, 20);
        QThread::msleep(5);
    }
    worker.join();
    dialog.reset();
    if (cancelled) *cancelled = false;
    if (!failure) return true;
    try {
        std::rethrow_exception(failure);
    } catch (const formats::Cancelled& exception) {
        if (cancelled) *cancelled = true;
        if (error) *error = QObject::tr("Cancelled");
    } catch (const std::exception& exception) {
        if (error) *error = QString::fromStdString(exception.what());
    }
    return false;
}

} // namespace chaintube::editor
