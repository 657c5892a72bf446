// require_regular_file: input files are read whole, so only a regular file will do.

#include "common/regular_file.hpp"

#include <filesystem>
#include <system_error>

#include "aloft/error.hpp"

namespace aloft {

void require_regular_file(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw InputError(path, {}, "not a regular file");
}

}  // namespace aloft
