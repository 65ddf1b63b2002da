#include "test_control.h"

#include "chaintube/editor/commands.h"
#include "main_window.h"

#include <QSocketNotifier>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace chaintube::editor {

namespace {

void reply(const std::string& line)
{
    std::fwrite(line.data(), 1, line.size(), stdout);
    std::fputc('\n', stdout);
    std::fflush(stdout);
}

/// One line from stdin, read byte by byte (nothing is buffered past the newline, so the
/// notifier below sees every later byte). Returns false at end of input.
bool readLine(std::string& line)
{
    line.clear();
    char c;
    while (true) {
        const ssize_t n = ::read(STDIN_FILENO, &c, 1);
        if (n <= 0) return !line.empty();
        if (c == '\n') return true;
        line += c;
    }
}

std::string handle(MainWindow& window, const std::string& line)
{
    Document& document = window.document();
    std::istringstream words(line);
    std::string verb, hose;
    words >> verb;
    if (verb == "modified") return std::string("modified ") + (document.isModified() ? "1" : "0");
    if (verb == "autosave-path") return "autosave-path " + window.autosavePath().toStdString();
    if (verb == "dump") {
        const std::string text = formats::serialiseProject(document.project());
        return "dump " + std::to_string(text.size()) + "\n" + text;
    }
    words >> hose;
    if (!document.hoseDefinition(hose)) return "error no hose '" + hose + "'";
    document.closeMerge(); // every request is its own undo step
    if (verb == "diameter") {
        double metres = 0;
        if (!(words >> metres) || !(metres > 0)) return "error diameter: expected metres > 0";
        document.undoStack()->push(makeChangeHoseField(document, hose,
                                                       &formats::HoseDefinition::outerDiameter,
                                                       metres, MergeId::HoseDiameter, "diameter"));
        return "ok";
    }
    if (verb == "segments") {
        int count = 0;
        if (!(words >> count) || count < 1) return "error segments: expected an integer >= 1";
        document.undoStack()->push(makeChangeHoseField(document, hose,
                                                       &formats::HoseDefinition::segmentCount,
                                                       count, MergeId::HoseSegments, "segments"));
        return "ok";
    }
    if (verb == "route") {
        std::size_t index = 0;
        Vec3 delta;
        if (!(words >> index >> delta.x() >> delta.y() >> delta.z()))
            return "error route: expected INDEX DX DY DZ";
        std::vector<Vec3> route = document.hoseDefinition(hose)->route;
        if (index >= route.size()) return "error route: index out of range";
        route[index] += delta;
        document.undoStack()->push(makeSetRoute(document, hose, route, "move route point"));
        return "ok";
    }
    return "error unknown request '" + verb + "'";
}

} // namespace

void installTestControl(MainWindow& window)
{
    window.ask = [](const QString& title, const QString&, QMessageBox::StandardButtons) {
        reply("ask " + title.toStdString());
        std::string answer;
        readLine(answer);
        return answer == "yes" ? QMessageBox::Yes : QMessageBox::No;
    };
    window.showError = [](const QString& title, const QString& text) {
        reply("shown-error " + title.toStdString() + ": " + text.toStdString());
    };
}

void startTestControl(MainWindow& window)
{
    auto* notifier = new QSocketNotifier(STDIN_FILENO, QSocketNotifier::Read, &window);
    QObject::connect(notifier, &QSocketNotifier::activated, &window, [&window, notifier] {
        std::string line;
        if (!readLine(line)) {
            notifier->setEnabled(false); // the driver closed stdin
            return;
        }
        reply(handle(window, line));
    });
    reply("ready");
}

} // namespace chaintube::editor
