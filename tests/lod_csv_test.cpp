// tools/io/lod_csv: QUERIES.csv of `glint lod` read strictly: the header rule, every data row parsed
// or rejected with its line and field, the ranges of the tile, and the size and line caps. No GPU.
#include "io/lod_csv.h"

#include <glint/glint.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>

namespace glint::io {
namespace {

// Expects parse_lod_csv(text) to throw Error(invalid_argument) whose one-line message holds every
// fragment.
void expect_error(const std::string& text, std::initializer_list<const char*> fragments, uint32_t atlas = 4096) {
  try {
    (void)parse_lod_csv(text, atlas, atlas);
    ADD_FAILURE() << "accepted: " << text.substr(0, 200);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument) << e.what();
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    for (const char* f : fragments) EXPECT_NE(m.find(f), std::string::npos) << "'" << f << "' not in: " << m;
  }
}

TEST(LodCsv, ReadsRowsHeaderCommentsAndLineEnds) {
  const LodCsv csv = parse_lod_csv(
      "dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y\r\n"
      "# a comment\n"
      "\n"
      " 0.015625 , 0,0,\t0.015625,256,256,0,0 \r\n"
      "+1e-3,-2.5e-2,0,1,1,1,4095,4095\n"
      "0.5,0.5,0.5,0.5,4096,16,0,4080",  // no line end at the end of the file
      4096, 4096);
  EXPECT_EQ(csv.header, "dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y");
  ASSERT_EQ(csv.queries.size(), 3u);
  ASSERT_EQ(csv.rows.size(), 3u);
  EXPECT_EQ(csv.rows[0], "0.015625 , 0,0,\t0.015625,256,256,0,0");
  EXPECT_EQ(csv.lines[0], 4u);
  EXPECT_EQ(csv.lines[1], 5u);
  EXPECT_EQ(csv.lines[2], 6u);
  EXPECT_EQ(csv.queries[0].dudx, 0.015625f);
  EXPECT_EQ(csv.queries[0].tex_w, 256.0f);
  EXPECT_EQ(csv.queries[1].dudx, 1e-3f);
  EXPECT_EQ(csv.queries[1].dvdx, -2.5e-2f);
  EXPECT_EQ(csv.queries[1].off_x, 4095.0f);
  EXPECT_EQ(csv.queries[2].tex_w, 4096.0f);
  EXPECT_EQ(csv.queries[2].off_y, 4080.0f);
  EXPECT_TRUE(parse_lod_csv("", 16, 16).queries.empty());
  EXPECT_TRUE(parse_lod_csv("# only a comment\n\n", 16, 16).queries.empty());
}

// A first row of tiny numbers (they underflow a float) is data, not a header: before, it was taken
// for a header and dropped without a word (one query fewer out than in).
TEST(LodCsv, AFirstRowOfUnderflowingNumbersIsData) {
  const LodCsv csv = parse_lod_csv("1e-45,0,0,1e-45,256,256,0,0\n1e-400,0,0,0,256,256,0,0\n", 4096, 4096);
  EXPECT_TRUE(csv.header.empty());
  ASSERT_EQ(csv.queries.size(), 2u);
  EXPECT_EQ(csv.queries[0].dudx, 1e-45f);  // the nearest float: the smallest subnormal
  EXPECT_EQ(csv.queries[1].dudx, 0.0f);
  // A first line mixing numbers and a typo is a bad data row, not a header.
  expect_error("0.1,0,0,0.1,256x,256,0,0\n", {"line 1", "field 5 (tex_w)", "'256x'", "not a number"});
  expect_error("nan,0,0,0.1,256,256,0,0\n", {"line 1", "field 1 (dudx)", "out of range", "finite"});
  // A header must name 8 fields; only the first content line may be one.
  expect_error("a,b,c\n", {"line 1", "header has 3 fields"});
  expect_error("0,0,0,0,1,1,0,0\ndudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y\n",
               {"line 2", "field 1 (dudx)", "'dudx'"});
  expect_error("# c\nh1,h2,h3,h4,h5,h6,h7,h8\nh1,h2,h3,h4,h5,h6,h7,h8\n", {"line 3", "not a number"});
}

TEST(LodCsv, NonFiniteAndOutOfRangeFieldsNameLineFieldAndRange) {
  const std::string ok = "0.1,0,0,0.1,256,256,0,0\n";
  expect_error(ok + "0.1,0,0,0.1,0,256,0,0\n", {"line 2", "field 5 (tex_w) = 0", "accepted 1 to 4096"});
  expect_error(ok + "0.1,0,0,0.1,256,-4,0,0\n", {"line 2", "field 6 (tex_h) = -4", "accepted 1 to 4096"});
  expect_error(ok + "0.1,0,0,0.1,0.5,256,0,0\n", {"line 2", "field 5 (tex_w) = 0.5"});
  expect_error(ok + "0.1,0,0,0.1,nan,256,0,0\n", {"line 2", "field 5 (tex_w)", "finite"});
  expect_error(ok + "0.1,0,0,0.1,256,inf,0,0\n", {"line 2", "field 6 (tex_h)", "finite"});
  expect_error(ok + "0.1,0,0,-inf,256,256,0,0\n", {"line 2", "field 4 (dvdy)", "finite"});
  expect_error(ok + "1e39,0,0,0.1,256,256,0,0\n", {"line 2", "field 1 (dudx) = 1e+39", "float range"});
  expect_error(ok + "1e400,0,0,0.1,256,256,0,0\n", {"line 2", "field 1 (dudx)", "out of range"});
  expect_error(ok + "0.1,0,0,0.1,8192,256,0,0\n", {"line 2", "field 5 (tex_w) = 8192", "atlas width"});
  expect_error(ok + "0.1,0,0,0.1,256,256,3841,0\n",
               {"line 2", "field 7 (off_x) = 3841", "0 to atlas width - tex_w = 3840", "inside the atlas"});
  expect_error(ok + "0.1,0,0,0.1,256,256,0,-1\n", {"line 2", "field 8 (off_y) = -1"});
  expect_error("0.1,0,0,0.1,8,8,0,0\n0.1,0,0,0.1,16,16,0,0\n", {"line 2", "field 5 (tex_w) = 16", "1 to 8"}, 8);
  // Every field of the kernel's validity test is checked here, so no accepted row gets level 0 for
  // being invalid: the tile sizes and offsets at the edges of their ranges are accepted.
  EXPECT_EQ(parse_lod_csv("0,0,0,0,1,1,0,0\n0,0,0,0,4096,4096,0,0\n0,0,0,0,1,1,4095,4095\n", 4096, 4096).queries.size(),
            3u);
}

TEST(LodCsv, MalformedLines) {
  expect_error("1,2,3\n", {"line 1", "has 3 fields", "expected 8 numbers"});
  expect_error("0,0,0,0,1,1,0,0,0\n", {"line 1", "more than 8 fields"});
  expect_error("0,0,0,0,1,1,0,\n", {"line 1", "field 8 (off_y)", "''", "not a number"});
  expect_error("0,0,0,0,1,1,0,0x10\n", {"line 1", "field 8 (off_y)", "not a number"});
  expect_error("0,0,0,0,1,1,0,+-1\n", {"line 1", "field 8", "not a number"});
  expect_error("0,0,0,0,1,1,0,1 2\n", {"line 1", "field 8", "not a number"});
  expect_error(std::string("0,0,0,0,1,1,0,0\n0,0,0,0,1,1\0,0,0\n", 32), {"line 2", "NUL byte"});
  expect_error(std::string(kMaxLodCsvLineBytes + 1, ' ') + "\n", {"line 1", "longer than 1024 bytes"});
  // A line of exactly the limit is fine (here: spaces, a blank line).
  EXPECT_TRUE(parse_lod_csv(std::string(kMaxLodCsvLineBytes, ' ') + "\r\n", 16, 16).queries.empty());
}

// Every prefix of a valid file either parses (ending at a row boundary, or a row whose numbers
// are still valid when cut) or is an error; never a crash.
TEST(LodCsv, EveryTruncationParsesOrFails) {
  const std::string text =
      "dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y\n0.25,0,0,0.25,64,64,128,128\n1,2,3,4,5,6,7,8\n";
  ASSERT_EQ(parse_lod_csv(text, 4096, 4096).queries.size(), 2u);
  for (size_t n = 0; n <= text.size(); ++n) {
    try {
      const LodCsv csv = parse_lod_csv(std::string_view(text.data(), n), 4096, 4096);
      EXPECT_LE(csv.queries.size(), 2u);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    }
  }
}

class LodCsvFile : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (std::filesystem::temp_directory_path() / ("glint_lod_csv_test_" + std::to_string(::getpid()) + ".csv"))
                .string();
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_;
};

// /dev/zero has no end and no line end: the reader stops at the line cap at once (before, it grew
// to gigabytes). The error names the path, the line and the cap.
TEST_F(LodCsvFile, DevZeroFailsFastAtTheLineCap) {
  const auto t0 = std::chrono::steady_clock::now();
  try {
    (void)load_lod_csv("/dev/zero", 4096, 4096);
    ADD_FAILURE() << "/dev/zero accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("/dev/zero: line 1: longer than 1024 bytes"), std::string::npos) << e.what();
  }
  // Functional bound, not a timing test: the read stops after one 64 KiB chunk, so even a slow
  // machine is far below a second; the unbounded reader took tens of seconds and gigabytes.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

// A sparse file larger than the size cap with no line end (what exhausted memory before): stopped
// at the line cap; and a file over the size cap.
TEST_F(LodCsvFile, FilesLargerThanTheCapAreRejected) {
  {
    std::ofstream f(path_, std::ios::binary);
    f << "0,0,0,0,1,1,0,0\n";
  }
  std::filesystem::resize_file(path_, kMaxLodCsvBytes + 4096);  // a hole of NUL bytes, no line end
  try {
    (void)load_lod_csv(path_, 4096, 4096);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    // The NUL run has no line end, so the line cap trips first; both caps name themselves.
    EXPECT_NE(std::string(e.what()).find("line 2: longer than 1024 bytes"), std::string::npos) << e.what();
  }
  // The size cap, with a smaller cap passed in (the default is 256 MiB): short lines, no line cap.
  {
    std::ofstream f(path_, std::ios::binary | std::ios::trunc);
    for (int i = 0; i < 2000; ++i) f << "0,0,0,0,1,1,0,0\n";  // 32,000 bytes
  }
  EXPECT_EQ(load_lod_csv(path_, 4096, 4096, 32000).queries.size(), 2000u);
  try {
    (void)load_lod_csv(path_, 4096, 4096, 31999);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("larger than 31999 bytes, the limit of QUERIES.csv"), std::string::npos)
        << e.what();
  }
}

TEST_F(LodCsvFile, MissingFilesAndDirectoriesAreIoFailures) {
  for (const std::string& p : {std::string("/no/such/file.csv"), std::filesystem::temp_directory_path().string()}) {
    try {
      (void)load_lod_csv(p, 16, 16);
      ADD_FAILURE() << p;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::io_failure) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(p + ": ", 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace glint::io
