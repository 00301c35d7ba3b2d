// Subcommands of the `dyncull` CLI. Each registerX adds its subcommand to the app; the
// subcommand's callback throws CLI::RuntimeError(code) to exit non-zero after printing
// its own one-line "error: ..." to stderr.
#pragma once

#include <CLI/CLI.hpp>

namespace dyncull::cli {

void registerView(CLI::App& app);
void registerRun(CLI::App& app);
void registerInspect(CLI::App& app);
void registerBench(CLI::App& app);
void registerSweep(CLI::App& app);
void registerSubdivide(CLI::App& app);
void registerExport(CLI::App& app);

}  // namespace dyncull::cli
