// The commands that run a module of the Python packages (`chainsim plot`, `chainsim fit`): find the
// interpreter and the packages, run `python3 -m MODULE ARGS...`, and return its exit code.
#include "cases/cli/python_command.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#ifndef CHAINSIM_PYTHON_DIR
#error "CHAINSIM_PYTHON_DIR (the source tree's python/ directory) must be defined by the build"
#endif

namespace chainsim {

namespace {

/// The directory of this executable ("" if unknown).
std::filesystem::path executable_dir() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

/// The interpreter: the python3 beside an installed executable (pip puts `chainsim` in a virtual
/// environment's bin/, beside the interpreter the packages were built for), else Debian's (it has
/// matplotlib and numpy), else the first python3 on PATH.
std::string python_interpreter(bool installed) {
  const std::filesystem::path dir = executable_dir();
  if (installed && !dir.empty() && access((dir / "python3").c_str(), X_OK) == 0) return (dir / "python3").string();
  const char* debian = "/usr/bin/python3";
  return access(debian, X_OK) == 0 ? debian : "python3";
}

/// The directories holding the packages: beside an installed executable (PREFIX/bin/chainsim ->
/// PREFIX/CHAINSIM_PYTHON_INSTALL_DIR) if `probe` is there, else the build tree's python/ (the
/// compiled module chainsim, when built) and the source tree's python/ the executable was built from.
std::string python_path(const std::string& probe, bool& installed) {
  installed = false;
#ifdef CHAINSIM_PYTHON_INSTALL_DIR
  std::error_code ec;
  const std::filesystem::path dir = executable_dir();
  if (!dir.empty()) {
    const std::filesystem::path packages = dir.parent_path() / CHAINSIM_PYTHON_INSTALL_DIR;
    if (std::filesystem::exists(packages / probe, ec)) {
      installed = true;
      return packages.string();
    }
  }
#endif
#ifdef CHAINSIM_PYTHON_BUILD_DIR
  return std::string(CHAINSIM_PYTHON_BUILD_DIR) + ":" + CHAINSIM_PYTHON_DIR;
#else
  return CHAINSIM_PYTHON_DIR;
#endif
}

}  // namespace

int run_python_module(const std::string& command, const std::string& module, const std::string& probe,
                      const std::vector<std::string>& module_args) {
  bool installed = false;
  const std::string path = python_path(probe, installed);
  bool found = false;
  std::string::size_type start = 0;
  while (!found && start <= path.size()) {
    const std::string::size_type end = std::min(path.find(':', start), path.size());
    std::error_code ec;
    found = std::filesystem::exists(std::filesystem::path(path.substr(start, end - start)) / probe, ec);
    start = end + 1;
  }
  if (!found) {
    std::cerr << fmt::format("chainsim: error: {}: {} is not in {} ({} runs it from the installed tree or the "
                             "source and build trees it was built from)\n",
                             command, probe, path, command);
    return 1;
  }
  const std::string python = python_interpreter(installed);
  std::vector<std::string> args = {python, "-m", module};
  args.insert(args.end(), module_args.begin(), module_args.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0) {
    std::cerr << fmt::format("chainsim: error: {}: cannot start {}: {}\n", command, python, std::strerror(errno));
    return 1;
  }
  if (pid == 0) {
    const char* old = std::getenv("PYTHONPATH");
    const std::string pythonpath = path + (old && *old ? std::string(":") + old : "");
    setenv("PYTHONPATH", pythonpath.c_str(), 1);
    execvp(argv[0], argv.data());
    std::cerr << fmt::format("chainsim: error: {} needs Python 3 with numpy and matplotlib: cannot run {}: {} "
                             "(install the Debian packages python3-matplotlib python3-numpy)\n",
                             command, python, std::strerror(errno));
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) {
      std::cerr << fmt::format("chainsim: error: {}: lost {}: {}\n", command, python, std::strerror(errno));
      return 1;
    }
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 127 ? 1 : WEXITSTATUS(status);
  std::cerr << fmt::format("chainsim: error: {}: {} ended by signal {}\n", command, python, WTERMSIG(status));
  return 1;
}

}  // namespace chainsim
