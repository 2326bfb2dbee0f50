// The command line's exit codes, and the one place a failure becomes one.
#pragma once

#include <exception>
#include <ostream>

namespace algray::cli {

// Bad input is 2 (nothing written), any other failure is 1.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

// Prints a failure as the command line does and returns its exit code: bad input (scene, output path, device)
// is 2, anything else 1.
int report_error(const std::exception& e, std::ostream& err);

}  // namespace algray::cli
