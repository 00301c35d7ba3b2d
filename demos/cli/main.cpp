// dyncull: command-line front end. Subcommands live in cmd_<name>.cpp.
#include <cstdio>
#include <cstring>
#include <string>

#include <CLI/CLI.hpp>

#include "dyncull/engine/heap_tuning.hpp"

#include "cli_util.hpp"
#include "commands.hpp"
#include "crash_report.hpp"

int main(int argc, char** argv) {
    dyncull::keepFreedHeapMemory();  // llvmpipe's per-draw blocks, not trimmed and faulted in again each frame
    dyncull::cli::installCrashReporter("dyncull");
    dyncull::cli::setCommandLine(argc, argv);
    CLI::App app{"dyncull: occlusion culling for dynamic scenes (two-level BSP + occlusion queries)"};
    app.require_subcommand(1);
    dyncull::cli::registerView(app);
    dyncull::cli::registerRun(app);
    dyncull::cli::registerInspect(app);
    dyncull::cli::registerBench(app);
    dyncull::cli::registerSweep(app);
    dyncull::cli::registerSubdivide(app);
    dyncull::cli::registerExport(app);
    // CLI11 reports a mistyped command as "A subcommand is required": name it instead.
    if (argc > 1 && argv[1][0] != '-') {
        std::string known;
        bool found = false;
        for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
            found = found || sub->get_name() == argv[1];
            known += (known.empty() ? "" : ", ") + sub->get_name();
        }
        if (!found) {
            std::fprintf(stderr, "error: unknown command '%s' (commands: %s; dyncull --help)\n", argv[1], known.c_str());
            return 1;
        }
    }
    int status = 0;
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        status = app.exit(e);
    }
    dyncull::cli::setCrashPhase("exit");
    return status;
}
