// GoogleTest main for the editor tests: a QApplication must exist before any Qt widget or
// OpenGL object. The platform comes from the environment (ctest sets offscreen for the
// document tests and runs the GUI tests under xvfb-run with xcb).
#include <QApplication>
#include <QFileInfo>
#include <QSettings>
#include <QStandardPaths>
#include <gtest/gtest.h>

int main(int argc, char** argv)
{
    ::testing::InitGoogleTest(&argc, argv);
    QApplication::setAttribute(Qt::AA_ShareOpenGLContexts);
    QApplication application(argc, argv);
    // Never touch the user's settings or autosaves; each test program has settings of its own
    // (ctest runs them side by side: one's recent files must not show in another's menu).
    QStandardPaths::setTestModeEnabled(true);
    QApplication::setOrganizationName("ChainTubeTests");
    QApplication::setApplicationName("chaintube-studio-tests-" +
                                     QFileInfo(QString::fromLocal8Bit(argv[0])).completeBaseName());
    QSettings::setDefaultFormat(QSettings::IniFormat);
    return RUN_ALL_TESTS();
}
