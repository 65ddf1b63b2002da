// ChainTube editor — runs a long job (scene import, project load, export) on a worker thread
// while a cancellable progress dialog keeps the window responsive.
#pragma once

#include <QString>
#include <functional>

class QWidget;

namespace chaintube::editor {

/// Runs `work(progress)` on a worker thread. `progress(fraction)` may be called from the
/// worker with 0 … 1 and returns false once the user pressed Cancel. Blocks (spinning the
/// event loop) until the work ends. Returns true if it finished; false if it threw, with the
/// exception's message in *error (formats::Cancelled gives *cancelled = true).
bool runWithProgress(QWidget* parent, const QString& label,
                     const std::function<void(const std::function<bool(double)>&)>& work,
                     QString* error, bool* cancelled = nullptr);

} // namespace chaintube::editor
