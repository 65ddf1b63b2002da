// chaintube-studio's test hook (`--test-control`): a line protocol on stdin/stdout with which a
// test drives the real binary — make edits through the same undo commands the panels use, read
// the project that is on screen, answer the questions the window asks (crash recovery). Used by
// tests/editor/hardening_recovery_test.cpp; never enabled without the option.
//
// The editor writes "ready" once its start-up project is open. Then requests (one per line)
// and replies (one line each, flushed):
//   diameter HOSE METRES          → "ok" | "error <why>"   (outer diameter edit)
//   segments HOSE COUNT           → "ok" | "error <why>"
//   route HOSE INDEX DX DY DZ     → "ok" | "error <why>"   (moves one route point, metres)
//   modified                      → "modified 0|1"
//   autosave-path                 → "autosave-path <path>"
//   dump                          → "dump <bytes>" then that many bytes: serialiseProject of
//                                   the project the window shows, then a newline
// Questions of the window (MainWindow::ask) are written as "ask <title>" and answered with a
// line "yes" or "no" read from stdin.
#pragma once

namespace chaintube::editor {

class MainWindow;

/// Installs the hook on `window` before anything is opened: replaces its question prompt and
/// error boxes.
void installTestControl(MainWindow& window);
/// After the start-up project is open (or recovered): writes "ready" and starts taking
/// requests on stdin (not earlier: opening runs nested event loops for its progress dialog).
void startTestControl(MainWindow& window);

} // namespace chaintube::editor
