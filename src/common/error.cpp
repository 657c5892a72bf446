// InputError: the message names the file, the place in it and the problem.

#include "aloft/error.hpp"

#include <utility>

namespace aloft {
namespace {

// "<file>:<line>:<column>: <path>: <problem>", leaving out what is unknown: an empty file or path,
// a line or column of 0 (a column is only shown after a line).
std::string format_input_error(const std::string& file, const SourcePlace& place, const std::string& problem) {
  std::string where = file;
  if (place.line > 0) {
    where.append(":").append(std::to_string(place.line));
    if (place.column > 0) where.append(":").append(std::to_string(place.column));
  }
  std::string message;
  auto append = [&message](const std::string& part) {
    if (part.empty()) return;
    if (!message.empty()) message += ": ";
    message += part;
  };
  append(where);
  append(place.path);
  append(problem);
  return message;
}

}  // namespace

InputError::InputError(std::string file, SourcePlace place, std::string problem)
    : std::runtime_error(format_input_error(file, place, problem)),
      file_(std::move(file)),
      place_(std::move(place)),
      problem_(std::move(problem)) {}

}  // namespace aloft
