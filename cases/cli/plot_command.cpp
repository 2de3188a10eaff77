// `chainsim plot RUN_DIR [...]`: draws a run with the Python package python/chainsim_plot (matplotlib).
// The C++ side only finds the interpreter and the package and passes the options on; the package checks
// them, reads the run and draws it, and its exit code is the command's (2: bad input, see docs/plotting.md).
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include "cases/cli/commands.hpp"

#ifndef CHAINSIM_PYTHON_DIR
#error "CHAINSIM_PYTHON_DIR (the source tree's python/ directory) must be defined by the build"
#endif

namespace chainsim {

namespace {

/// Debian's interpreter (it has matplotlib and numpy), else the first python3 on PATH.
std::string python_interpreter() {
  const char* debian = "/usr/bin/python3";
  return access(debian, X_OK) == 0 ? debian : "python3";
}

/// The interpreter's arguments after the interpreter: -m chainsim_plot RUN_DIR [--option=value ...].
std::vector<std::string> plot_arguments(const PlotCommandOptions& options) {
  std::vector<std::string> args = {"-m", "chainsim_plot", options.run_dir};
  if (options.animate) args.emplace_back("--animate");
  const std::pair<const char*, const std::string*> values[] = {
      {"--speed", &options.speed}, {"--fps", &options.fps}, {"--times", &options.times}, {"--format", &options.format}};
  for (const auto& [name, value] : values)
    if (!value->empty()) args.push_back(std::string(name) + "=" + *value);
  return args;
}

}  // namespace

namespace {

/// The directory holding chainsim_plot: beside an installed executable (PREFIX/bin/chainsim ->
/// PREFIX/CHAINSIM_PYTHON_INSTALL_DIR), else the source tree the executable was built from.
std::string python_dir() {
#ifdef CHAINSIM_PYTHON_INSTALL_DIR
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed = exe.parent_path().parent_path() / CHAINSIM_PYTHON_INSTALL_DIR;
    if (std::filesystem::exists(installed / "chainsim_plot" / "__main__.py", ec)) return installed.string();
  }
#endif
  return CHAINSIM_PYTHON_DIR;
}

}  // namespace

int run_plot_command(const PlotCommandOptions& options) {
  const std::string python_path = python_dir();
  const std::filesystem::path package = std::filesystem::path(python_path) / "chainsim_plot";
  if (!std::filesystem::exists(package / "__main__.py")) {
    std::cerr << fmt::format("chainsim: error: plot: the plotting package is not at {} (chainsim plot runs it from "
                             "the installed tree or the source tree it was built from)\n",
                             package.string());
    return 1;
  }
  const std::string python = python_interpreter();
  std::vector<std::string> args = plot_arguments(options);
  args.insert(args.begin(), python);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0) {
    std::cerr << fmt::format("chainsim: error: plot: cannot start {}: {}\n", python, std::strerror(errno));
    return 1;
  }
  if (pid == 0) {
    const char* old = std::getenv("PYTHONPATH");
    const std::string path = python_path + (old && *old ? std::string(":") + old : "");
    setenv("PYTHONPATH", path.c_str(), 1);
    execvp(argv[0], argv.data());
    std::cerr << fmt::format("chainsim: error: plot needs Python 3 with numpy and matplotlib: cannot run {}: {} "
                             "(install the Debian packages python3-matplotlib python3-numpy)\n",
                             python, std::strerror(errno));
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) {
      std::cerr << fmt::format("chainsim: error: plot: lost {}: {}\n", python, std::strerror(errno));
      return 1;
    }
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 127 ? 1 : WEXITSTATUS(status);
  std::cerr << fmt::format("chainsim: error: plot: {} ended by signal {}\n", python, WTERMSIG(status));
  return 1;
}

}  // namespace chainsim
