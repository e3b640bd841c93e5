// Where the running program's binary lies: installed programs find their files and their sibling
// programs from it (the build tree has the same layout as an installation).
#pragma once

#include <filesystem>
#include <system_error>

namespace fluidcast {

inline std::filesystem::path program_folder() {
  std::error_code error;
  return std::filesystem::read_symlink("/proc/self/exe", error).parent_path();
}

}  // namespace fluidcast
