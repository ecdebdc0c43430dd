#pragma once
// Each `strata` subcommand registers itself on the app. A command that fails prints one line
// on stderr and throws CLI::RuntimeError(exit code).
#include <CLI/CLI.hpp>

#include <string>
#include <string_view>

namespace strata::app {

void addGpuInfoCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addFloodCommands(CLI::App& app);
void addGenerateCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addCheckCommand(CLI::App& app);
void addIngestCommand(CLI::App& app);
void addExportCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);

/// Whether strata runs as one rank of an MPI job (launched by mpirun or mpiexec: main initialises
/// MPI then), this process's rank and the number of ranks; else false, 0, 1.
struct MpiLaunch {
  bool active = false;
  int rank = 0, size = 1;
};
const MpiLaunch& mpiLaunch();

/// Ends subcommand `command` with one line on stderr, "strata COMMAND: WHAT", and exit code `code`.
[[noreturn]] void exitCommand(std::string_view command, const std::string& what, int code = 1);
/// A number as messages and metadata print it (printf's %g: six significant digits).
std::string number(double v);

}  // namespace strata::app
