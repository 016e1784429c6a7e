#include "input_file.hpp"

#include <filesystem>
#include <fstream>

#include "sh/error.hpp"

namespace sh::rt {

void check_input_file(const std::string& path, const std::string& what) {
  std::error_code error;
  auto status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) throw Error(path + ": cannot open " + what + ": no such file");
  if (!std::filesystem::is_regular_file(status)) throw Error(path + ": cannot open " + what + ": not a regular file");
  if (!std::ifstream(path)) throw Error(path + ": cannot open " + what);
}

}  // namespace sh::rt
