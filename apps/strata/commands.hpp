#pragma once
// Each `strata` subcommand registers itself on the app. A command that fails prints one line
// on stderr and throws CLI::RuntimeError(exit code).
#include <CLI/CLI.hpp>

namespace strata::app {

void addGpuInfoCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addFloodCommands(CLI::App& app);
void addGenerateCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addCheckCommand(CLI::App& app);
void addIngestCommand(CLI::App& app);
void addExportCommand(CLI::App& app);

}  // namespace strata::app
