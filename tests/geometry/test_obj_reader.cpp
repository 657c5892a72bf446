// read_obj() / parse_obj_text(): good files, every kind of malformed line with its line number, missing
// files, arbitrary bytes; and the InputError message format.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "aloft/error.hpp"
#include "aloft/geometry.hpp"
#include "geometry/obj_reader.hpp"

namespace aloft {
namespace {

namespace fs = std::filesystem;

// Writes `text` to a file in the temporary directory named after the running test and `name`.
fs::path write_temp(const std::string& name, const std::string& text) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path path = fs::temp_directory_path() / ("aloft_" + std::string(info->name()) + "_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A unit cube centred at the origin; corner k+1 has coordinates +-0.5 with bits 0, 1, 2 of k choosing +
// along x, y, z. Faces are quads, counter-clockwise seen from outside, in every face-vertex form, one of
// them with negative indices, with comments, groups, materials, normals, texture coordinates, tabs, a w
// coordinate and a CRLF line.
const char* kCube =
    "# cube\n"
    "mtllib cube.mtl\n"
    "o cube\n"
    "v -0.5 -0.5 -0.5\n"
    "v 0.5 -0.5 -0.5\n"
    "v -0.5 0.5 -0.5\n"
    "v 0.5 0.5 -0.5\r\n"
    "v -0.5 -0.5 0.5\n"
    "v\t0.5 -0.5 0.5 1.0\n"
    "v -0.5 0.5 0.5   # trailing comment\n"
    "v +0.5 0.5 5e-1\n"
    "\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn -1 0 0\nvn 1 0 0\n"
    "g sides\nusemtl red\ns off\n"
    "f 1/1/1 5/2/1 7/3/1 3/4/1\n"
    "f 2//2 4//2 8//2 6//2\n"
    "f 1/1 2/2 6/3 5/4\n"
    "f -6 -2 -1 -5\n"
    "f 1 3 4 2\n"
    "f 5 6 8 7 # top\n";

TEST(ObjReader, ReadsAGoodFile) {
  const fs::path path = write_temp("cube.obj", kCube);
  const TriangleMesh m = read_obj(path.string()).mesh;
  ASSERT_EQ(m.vertices.size(), 8u);
  ASSERT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices[7], Vec3(0.5, 0.5, 0.5));
  EXPECT_EQ(m.vertices[5], Vec3(0.5, -0.5, 0.5));
  // Quads are fanned from their first vertex; negative indices count back from the latest vertex.
  EXPECT_EQ(m.triangles[0], (std::array<int, 3>{0, 4, 6}));
  EXPECT_EQ(m.triangles[1], (std::array<int, 3>{0, 6, 2}));
  EXPECT_EQ(m.triangles[6], (std::array<int, 3>{2, 6, 7}));
  EXPECT_EQ(m.triangles[7], (std::array<int, 3>{2, 7, 3}));
  EXPECT_EQ(closed_mesh_problem(m), std::nullopt);
  EXPECT_NEAR(polyhedron_mass_properties(m).volume, 1.0, 1e-12);  // 1e-12: exact up to rounding
  fs::remove(path);
}

// Each triangle keeps the line and column of the face it was fanned from, for the closed-mesh check's
// messages: kCube's six quads are on lines 22 to 27, two triangles each.
TEST(ObjReader, TrianglesKeepTheirFacesPlace) {
  const ObjMesh obj = parse_obj_text(kCube, "cube.obj");
  ASSERT_EQ(obj.faces.size(), obj.mesh.triangles.size());
  for (size_t t = 0; t < obj.faces.size(); ++t) {
    EXPECT_EQ(obj.faces[t].line, 22 + static_cast<int>(t / 2)) << t;
    EXPECT_EQ(obj.faces[t].column, 1) << t;
  }
  const ObjMesh indented = parse_obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n\n  \tf 1 2 3\n", "indented.obj");
  ASSERT_EQ(indented.faces.size(), 1u);
  EXPECT_EQ(indented.faces[0].line, 5);
  EXPECT_EQ(indented.faces[0].column, 4);  // the 'f', after two spaces and a tab
}

TEST(ObjReader, NegativeIndicesAreRelativeToTheVerticesSoFar) {
  const TriangleMesh m = parse_obj_text(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\nf 1 -1 -4\n", "rel.obj").mesh;
  ASSERT_EQ(m.triangles.size(), 3u);
  EXPECT_EQ(m.triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<int, 3>{3, 4, 5}));
  EXPECT_EQ(m.triangles[2], (std::array<int, 3>{0, 5, 2}));
}

TEST(ObjReader, LineEndingsOfEveryKindCountLines) {
  // \n, \r\n and \r each end one line: the bad vertex is on line 4 in each.
  for (const std::string eol : {"\n", "\r\n", "\r"}) {
    const std::string text = "v 0 0 0" + eol + "v 1 0 0" + eol + eol + "v 1 2" + eol + "f 1 2 3" + eol;
    try {
      parse_obj_text(text, "eol.obj");
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.place().line, 4) << e.what();
    }
  }
}

struct BadCase {
  std::string text;
  int line;
  std::string words;
};

TEST(ObjReader, MalformedFilesNameFileAndLine) {
  const std::string three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::vector<BadCase> cases = {
      {"v 0 0 0\nv 1 0 0\n\n# comment\nv 1 2\nf 1 2 3\n", 5, "expected 3 coordinates after 'v', got 2"},
      {"v\n", 1, "expected 3 coordinates after 'v', got 0"},
      {three + "f 1 2 9\n", 4, "face index 9 out of range (3 vertices so far)"},
      {three + "f 1 -4 2\n", 4, "face index -4 out of range (3 vertices so far)"},
      {"v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", 3, "face index 3 out of range (2 vertices so far)"},
      {three + "f 1 0 2\n", 4, "face index 0 is invalid"},
      {three + "f 1 2 99999999999999999999999\n", 4, "out of range"},
      {"v 0 0 nan\n", 1, "non-finite coordinate 'nan'"},
      {"v 0 inf 0\n", 1, "non-finite coordinate"},
      {"v 0 0 1e999\n", 1, "non-finite coordinate '1e999'"},
      {"v 0 0 abc\n", 1, "expected a number after 'v', got 'abc'"},
      {"v 0 0 1.5.2\n", 1, "expected a number"},
      {"v 0 0 0 junk\n", 1, "expected a number"},
      {three + "f 1 2\n", 4, "face with fewer than 3 vertices"},
      {three + "f\n", 4, "face with fewer than 3 vertices"},
      {three + "f 1/x 2 3\n", 4, "malformed face vertex '1/x'"},
      {three + "f 1 2/1/1/1 3\n", 4, "malformed face vertex"},
      {three + "f 1 2 3/\n", 4, "malformed face vertex"},
      {three + "f a b c\n", 4, "malformed face vertex 'a'"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.text);
    const fs::path path = write_temp("bad.obj", c.text);
    try {
      read_obj(path.string());
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), path.string());
      EXPECT_EQ(e.place().line, c.line) << what;
      EXPECT_NE(what.find(path.string() + ":" + std::to_string(c.line) + ":"), std::string::npos) << what;
      EXPECT_NE(what.find(c.words), std::string::npos) << what;
    }
    fs::remove(path);
  }
}

TEST(ObjReader, ColumnPointsAtTheBadToken) {
  try {
    parse_obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2   17\n", "col.obj");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "col.obj:4:9: face index 17 out of range (3 vertices so far)");
  }
}

TEST(ObjReader, FileWithoutFaces) {
  for (const std::string& text : {std::string(), std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\n"), std::string("# nothing\n")}) {
    try {
      parse_obj_text(text, "empty.obj");
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(), "empty.obj: file has no faces");
    }
  }
}

// A UTF-8 byte-order mark is skipped: the first line's vertex is read (before, "\xEF\xBB\xBFv" was an
// unknown statement, and "f 1 2 3" on line 4 was out of range with 2 vertices so far). Columns on the
// first line do not count the mark.
TEST(ObjReader, Utf8ByteOrderMarkIsSkipped) {
  const TriangleMesh m = parse_obj_text("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "bom.obj").mesh;
  ASSERT_EQ(m.vertices.size(), 3u);
  EXPECT_EQ(m.vertices[0], Vec3(0, 0, 0));
  ASSERT_EQ(m.triangles.size(), 1u);
  try {
    parse_obj_text("\xEF\xBB\xBFv 0 x 0\n", "bom.obj");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "bom.obj:1:5: expected a number after 'v', got 'x'");
  }
  // Only at the start: elsewhere the mark is not whitespace, and the statement is unknown.
  EXPECT_THROW(parse_obj_text("v 0 0 0\n\xEF\xBB\xBFv 1 0 0\nv 0 1 0\nf 1 2 3\n", "bom.obj"), InputError);
}

// UTF-16 text, with or without its byte-order mark, is refused as such (it used to end in "file has no
// faces", every line being an unknown statement of letters and NULs).
TEST(ObjReader, Utf16IsRefusedAsNotUtf8) {
  const std::string ascii = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::string le, be;
  for (char c : ascii) {
    le += std::string{c, '\0'};
    be += std::string{'\0', c};
  }
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"\xFF\xFE" + le, "utf16.obj:1:1: the file is UTF-16"},
      {"\xFE\xFF" + be, "utf16.obj:1:1: the file is UTF-16"},
      {le, "utf16.obj:1:2: NUL byte: the file is UTF-16 or not text"},
      {be, "utf16.obj:1:1: NUL byte: the file is UTF-16 or not text"},
      {ascii + "# a comment" + std::string(1, '\0') + "\n", "utf16.obj:5:12: NUL byte"},  // even in a comment
  };
  for (const auto& [text, start] : cases) {
    try {
      parse_obj_text(text, "utf16.obj");
      ADD_FAILURE() << "no error for " << start;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(start, 0), 0u) << what;
      EXPECT_NE(what.find("OBJ files must be ASCII or UTF-8"), std::string::npos) << what;
    }
  }
}

TEST(ObjReader, MissingFile) {
  const std::string path = (fs::temp_directory_path() / "aloft_no_such_dir" / "fish.obj").string();
  try {
    read_obj(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open file: No such file or directory");
  }
  // A directory, or a device that has no end (read until memory ran out when read_obj was called directly).
  for (const std::string& not_a_file : {fs::temp_directory_path().string(), std::string("/dev/zero")}) {
    try {
      read_obj(not_a_file);
      ADD_FAILURE() << "no error for " << not_a_file;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), not_a_file + ": not a regular file");
    }
  }
}

// Whatever the bytes, parsing either returns a mesh whose indices are all in range or throws InputError.
void expect_parses_or_rejects(const std::string& text) {
  try {
    const ObjMesh obj = parse_obj_text(text, "junk.obj");
    const TriangleMesh& m = obj.mesh;
    ASSERT_FALSE(m.triangles.empty());
    ASSERT_EQ(obj.faces.size(), m.triangles.size());
    for (const auto& t : m.triangles)
      for (int k : t) ASSERT_TRUE(k >= 0 && k < static_cast<int>(m.vertices.size()));
    for (const Vec3& v : m.vertices) ASSERT_TRUE(v.allFinite());
  } catch (const InputError&) {
  }
}

TEST(ObjReader, SurvivesArbitraryBytes) {
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 200);
  const std::string alphabet = "vf 0123456789-+./#\neE\tnaif\r";
  std::uniform_int_distribution<size_t> pick(0, alphabet.size() - 1);
  for (int i = 0; i < 3000; ++i) {
    std::string text;
    const int n = length(rng);
    // Half pure junk, half junk from OBJ's own characters (which reaches deeper into the parser).
    for (int k = 0; k < n; ++k) text += i % 2 ? static_cast<char>(byte(rng)) : alphabet[pick(rng)];
    expect_parses_or_rejects(text);
    expect_parses_or_rejects(kCube + text);
  }
  // Single-byte mutations of the good file.
  const std::string cube = kCube;
  for (size_t k = 0; k < cube.size(); ++k) {
    std::string text = cube;
    text[k] = static_cast<char>(byte(rng));
    expect_parses_or_rejects(text);
  }
  // Extremes: a very long line, enormous numbers, a NUL byte.
  expect_parses_or_rejects("v " + std::string(1 << 20, '9') + " 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
  expect_parses_or_rejects("v 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 " + std::string(1 << 18, ' ') + "\n");
  expect_parses_or_rejects("v 1e308 -1e308 1e-320\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf -99999999999999999999 1 2\n");
  const char with_nul[] = "v 0 0 0\0 1 2\nf 1 1 1\n";
  expect_parses_or_rejects(std::string(with_nul, sizeof with_nul - 1));
}

TEST(InputError, MessageOmitsUnknownParts) {
  EXPECT_STREQ(InputError("fish.obj", {"", 7, 0}, "expected 3 coordinates after 'v'").what(),
               "fish.obj:7: expected 3 coordinates after 'v'");
  EXPECT_STREQ(InputError("two.json", {"components[2].joint", 0, 0}, "unknown joint").what(),
               "two.json: components[2].joint: unknown joint");
  EXPECT_STREQ(InputError("mobiles/two-fish.json", {"components[2].shapes[0].sphere.radius", 12, 7},
                          "must be positive, got -0.01")
                   .what(),
               "mobiles/two-fish.json:12:7: components[2].shapes[0].sphere.radius: must be positive, got -0.01");
  EXPECT_STREQ(InputError("a.obj", {"", 0, 5}, "p").what(), "a.obj: p");  // a column without a line is not shown
  EXPECT_STREQ(InputError("", {}, "no file").what(), "no file");
  const InputError e("f.json", {"x", 3, 4}, "bad");
  EXPECT_EQ(e.file(), "f.json");
  EXPECT_EQ(e.place().path, "x");
  EXPECT_EQ(e.place().line, 3);
  EXPECT_EQ(e.place().column, 4);
  EXPECT_EQ(e.problem(), "bad");
}

}  // namespace
}  // namespace aloft
