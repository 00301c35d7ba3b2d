// dyncull: command-line front end. Subcommands live in cmd_<name>.cpp.
#include <CLI/CLI.hpp>

#include "cli_util.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
    dyncull::cli::setCommandLine(argc, argv);
    CLI::App app{"dyncull: occlusion culling for dynamic scenes (two-level BSP + occlusion queries)"};
    app.require_subcommand(1);
    dyncull::cli::registerView(app);
    dyncull::cli::registerRun(app);
    dyncull::cli::registerInspect(app);
    dyncull::cli::registerBench(app);
    dyncull::cli::registerSweep(app);
    dyncull::cli::registerSubdivide(app);
    CLI11_PARSE(app, argc, argv);
    return 0;
}
