// chaintube-studio — the ChainTube editor. Usage: chaintube-studio [--root NAME=DIR]… [PROJECT]
#include "main_window.h"

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
    parser.addPositionalArgument("project", "Project file (*.ctproj) to open");
    parser.process(application);
    QString error;
    const auto roots = chaintube::editor::editorRoots(parser.values("root"), &error);
    if (!error.isEmpty()) {
        std::fprintf(stderr, "chaintube-studio: %s\n", qPrintable(error));
        return 2;
    }
    chaintube::editor::MainWindow window(roots);
    window.show();
    if (!parser.positionalArguments().isEmpty())
        window.openFile(parser.positionalArguments().first());
    else
        window.recoverUntitled();
    return application.exec();
}
