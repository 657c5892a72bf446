#pragma once
// Errors that name the file, the place in it and what is wrong.

#include <stdexcept>
#include <string>

namespace aloft {

// Where something is in an input file: a JSON path such as `components[3].shapes[0].radius`
// (empty for the whole file) and the 1-based line and column where known (0 when not).
struct SourcePlace {
  std::string path;
  int line = 0;
  int column = 0;
};

// A problem in an input file (mobile JSON, OBJ mesh, audio). what() is the full, user-facing message:
//   "mobiles/two-fish.json:12:7: components[2].shapes[0].sphere.radius: must be positive, got -0.01"
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, SourcePlace place, std::string problem);

  const std::string& file() const { return file_; }
  const SourcePlace& place() const { return place_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_;
  SourcePlace place_;
  std::string problem_;
};

}  // namespace aloft
