// glint lod: evaluates atlas-aware LOD queries from a CSV file on the GPU (LodBatch) and writes
// them back with a `lod` column. Rows: dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y; an optional
// header line (first field not a number) is kept and extended; blank lines and lines starting
// with '#' are skipped.
#include <glint/lod.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "cli/commands.h"
#include "core/barriers.h"
#include "core/resources.h"

namespace glint::cli {
namespace {

constexpr size_t kMaxQueries = 4'194'240;  // LodBatch's per-call limit

struct Row {
  std::string text;  // the input row as written (trimmed)
  LodQuery query;
};

bool parse_float(const std::string& field, float& out) {
  const char* s = field.c_str();
  char* end = nullptr;
  errno = 0;
  const float v = std::strtof(s, &end);
  while (end && (*end == ' ' || *end == '\t')) ++end;
  if (end == s || !end || *end != '\0' || errno == ERANGE) return false;
  out = v;
  return true;
}

std::vector<Row> read_queries(const std::string& path, std::string& header) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::io_failure, path + ": cannot open: " + std::strerror(errno));
  std::vector<Row> rows;
  std::string line;
  size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    float v[8];
    bool numeric = fields.size() == 8;
    for (size_t i = 0; numeric && i < 8; ++i) numeric = parse_float(fields[i], v[i]);
    if (!numeric) {
      float first;
      if (rows.empty() && header.empty() && !fields.empty() && !parse_float(fields[0], first)) {
        header = line;  // a header row
        continue;
      }
      throw Error(ErrorCode::io_failure, path + ":" + std::to_string(line_no) +
                                             ": expected 8 numbers dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y");
    }
    if (rows.size() >= kMaxQueries) {
      throw Error(ErrorCode::io_failure, path + ": more than " + std::to_string(kMaxQueries) + " queries");
    }
    rows.push_back({line, {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]}});
  }
  if (in.bad()) throw Error(ErrorCode::io_failure, path + ": read error");
  return rows;
}

}  // namespace

Command add_lod_command(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("lod", "Atlas-aware mip level of each query in a CSV file, computed on the GPU");
  struct Options {
    std::string atlas = "4096x4096", device, in, out;
    uint32_t levels = 13;
    float aniso = 0.0f, bias = 0.0f, padding = -1.0f;
  };
  auto o = std::make_shared<Options>();
  sub->add_option("--atlas", o->atlas, "atlas size WxH in texels");
  sub->add_option("--levels", o->levels, "mip levels of the atlas (1 to 17)")->required();
  sub->add_option("--aniso", o->aniso, "anisotropic LOD with this maxAnisotropy (1 to 64); 0 = isotropic");
  sub->add_option("--bias", o->bias, "LOD bias (-16 to 16)");
  sub->add_option("--padding", o->padding, "texels of padding around each tile; caps the level (0 to 65536)");
  sub->add_option("QUERIES.csv", o->in, "rows dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y")->required();
  sub->add_option("OUT.csv", o->out, "the rows again with a lod column")->required();
  add_device_option(*sub, o->device);
  return {sub, [o, sub] {
            const VkExtent2D size = parse_size("--atlas", o->atlas);
            LodAtlasConfig atlas;
            atlas.atlas_width = size.width;
            atlas.atlas_height = size.height;
            atlas.levels = o->levels;
            atlas.bias = o->bias;
            if (sub->count("--aniso")) {
              atlas.anisotropic = true;
              atlas.max_anisotropy = o->aniso;
            }
            if (sub->count("--padding")) {
              if (!(o->padding >= 0.0f)) {
                throw Error(ErrorCode::invalid_argument, "--padding = " + std::to_string(o->padding) +
                                                             " is out of range: accepted 0 to 65536");
              }
              atlas.padding_texels = o->padding;
            }
            atlas.validate();
            check_output_path(o->out);
            std::string header;
            const std::vector<Row> rows = read_queries(o->in, header);

            Context ctx = make_context(o->device);
            std::vector<float> levels(rows.size());
            if (!rows.empty()) {
              const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
              detail::OwnedBuffer qbuf(ctx, rows.size() * sizeof(LodQuery), usage, true);
              detail::OwnedBuffer lbuf(ctx, rows.size() * sizeof(float), usage, true);
              auto* q = static_cast<LodQuery*>(qbuf.mapped());
              for (size_t i = 0; i < rows.size(); ++i) q[i] = rows[i].query;
              qbuf.flush();
              Buffer qv{qbuf.buffer(), 0, qbuf.size(), usage, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT};
              Buffer lv{lbuf.buffer(), 0, lbuf.size(), usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
              LodBatch batch(ctx);
              ctx.run_once([&](VkCommandBuffer cmd) {
                batch.record(cmd, qv, lv, static_cast<uint32_t>(rows.size()), atlas);
                detail::Barriers b;
                b.use(lv, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
                b.flush(cmd);
              });
              lbuf.invalidate();
              std::memcpy(levels.data(), lbuf.mapped(), levels.size() * sizeof(float));
            }
            std::ofstream out(o->out);
            if (!out) throw Error(ErrorCode::io_failure, o->out + ": cannot open for writing");
            if (!header.empty()) out << header << ",lod\n";
            char num[32];
            for (size_t i = 0; i < rows.size(); ++i) {
              std::snprintf(num, sizeof num, "%.6f", double(levels[i]));
              out << rows[i].text << ',' << num << '\n';
            }
            out.close();
            if (!out) throw Error(ErrorCode::io_failure, o->out + ": write failed");
            std::printf("%zu queries on %s -> %s\n", rows.size(), ctx.info().name.c_str(), o->out.c_str());
          }};
}

}  // namespace glint::cli
