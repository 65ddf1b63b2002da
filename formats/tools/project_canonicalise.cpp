// ctproj-canonicalise: loads project files (migrating older versions, validating everything)
// and saves them back in canonical form, atomically. Used to produce the committed samples.
//
//   ctproj-canonicalise [--root name=folder]… file.ctproj…
#include "chaintube/formats/project.h"

#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

int main(int argc, char** argv)
{
    chaintube::formats::ProjectLoadOptions options;
    int files = 0;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--root") == 0 && i + 1 < argc) {
            const std::string mapping = argv[++i];
            const size_t equals = mapping.find('=');
            if (equals == std::string::npos) {
                std::fprintf(stderr, "--root expects name=folder, got %s\n", mapping.c_str());
                return 2;
            }
            options.roots[mapping.substr(0, equals)] = mapping.substr(equals + 1);
            continue;
        }
        try {
            const auto project = chaintube::formats::loadProject(argv[i], options);
            chaintube::formats::saveProject(project, argv[i], options);
            ++files;
        } catch (const std::exception& error) {
            std::fprintf(stderr, "%s\n", error.what());
            return 1;
        }
    }
    if (files == 0) {
        std::fprintf(stderr, "usage: %s [--root name=folder]... file.ctproj...\n", argv[0]);
        return 2;
    }
    return 0;
}
