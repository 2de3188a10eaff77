#pragma once
/// @file python_command.hpp
/// Running a module of the Python packages as a chainsim command (`chainsim plot`, `chainsim fit`).
#include <string>
#include <vector>

namespace chainsim {

/// Runs /usr/bin/python3 (else python3 on PATH) -m `module` `module_args`... with PYTHONPATH led by the
/// directories of the packages: the installed tree beside the executable if it holds `probe` (a path
/// such as "chainsim_plot/__main__.py"), else the build tree's python/ and the source tree's python/.
/// Returns the module's exit code; 1 (with a message naming `command`) if it cannot be started.
int run_python_module(const std::string& command, const std::string& module, const std::string& probe,
                      const std::vector<std::string>& module_args);

}  // namespace chainsim
