// chaintube-studio — the ChainTube editor. Usage: chaintube-studio [--root NAME=DIR]… [PROJECT]
#include "main_window.h"
#include "test_control.h"

#include <QApplication>
#include <QCommandLineParser>
#include <cstdio>

int main(int argc, char** argv)
{
    QApplication::setAttribute(Qt::AA_ShareOpenGLContexts);
    QApplication application(argc, argv);
    QApplication::setOrganizationName("ChainTube");
    QApplication::setApplicationName("chaintube-studio");
    QCommandLineParser parser;
    parser.setApplicationDescription("ChainTube Studio: lay out deformable hoses in CAD scenes");
    parser.addHelpOption();
    parser.addOption({"root", "Named root for scene paths like scenes:engine.glb", "NAME=DIR"});
    // For tests (tests/editor/hardening_recovery_test.cpp): a shorter autosave interval, and
    // the stdin/stdout hook of test_control.h.
    parser.addOption({"autosave-interval", "Autosave every MS milliseconds (default 30000)", "MS"});
    parser.addOption({"test-control", "Take test requests on stdin (see test_control.h)"});
    parser.addPositionalArgument("project", "Project file (*.ctproj) to open");
    parser.process(application);
    QString error;
    const auto roots = chaintube::editor::editorRoots(parser.values("root"), &error);
    if (!error.isEmpty()) {
        std::fprintf(stderr, "chaintube-studio: %s\n", qPrintable(error));
        return 2;
    }
    chaintube::editor::MainWindow window(roots);
    if (parser.isSet("autosave-interval")) {
        bool ok = false;
        const int milliseconds = parser.value("autosave-interval").toInt(&ok);
        if (!ok || milliseconds < 10) {
            std::fprintf(stderr,
                         "chaintube-studio: --autosave-interval expects milliseconds "
                         ">= 10, got '%s'\n",
                         qPrintable(parser.value("autosave-interval")));
            return 2;
        }
        window.setAutosaveInterval(milliseconds);
    }
    if (parser.isSet("test-control")) chaintube::editor::installTestControl(window);
    window.show();
    if (!parser.positionalArguments().isEmpty())
        window.openFile(parser.positionalArguments().first());
    else
        window.recoverUntitled();
    if (parser.isSet("test-control")) chaintube::editor::startTestControl(window);
    return application.exec();
}
