// glint lod: evaluates atlas-aware LOD queries from a CSV file on the GPU (LodBatch) and writes
// them back with a `lod` column. The input format, its optional header and its bounds are those of
// io::parse_lod_csv() (tools/io/lod_csv.h, docs/LOD.md): every data row is either evaluated or
// rejected with its line number, never dropped.
#include <glint/lod.h>

#include <cstdio>
#include <cstring>
#include <memory>

#include "cli/commands.h"
#include "core/barriers.h"
#include "core/resources.h"
#include "io/atomic_outputs.h"
#include "io/lod_csv.h"

namespace glint::cli {

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
  sub->add_option("QUERIES.csv", o->in,
                  "rows dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y; optional header of 8 names (docs/LOD.md)")
      ->required();
  sub->add_option("OUT.csv", o->out, "the rows again with a lod column")->required();
  add_device_option(*sub, o->device);
  return {sub, [o, sub] {
            const VkExtent2D size = parse_size("--atlas", o->atlas);
            LodAtlasConfig atlas;
            atlas.atlas_width = size.width;
            atlas.atlas_height = size.height;
            atlas.levels = o->levels;
            atlas.bias = o->bias;
            // --aniso 0 (the default) is isotropic, as --help says; anything else is a maxAnisotropy.
            if (o->aniso != 0.0f) {
              atlas.anisotropic = true;
              atlas.max_anisotropy = o->aniso;
            }
            if (sub->count("--padding")) {
              if (!(o->padding >= 0.0f)) {
                throw Error(ErrorCode::invalid_argument,
                            "--padding = " + std::to_string(o->padding) + " is out of range: accepted 0 to 65536");
              }
              atlas.padding_texels = o->padding;
            }
            atlas.validate();
            check_output_path(o->out);
            const io::LodCsv csv = io::load_lod_csv(o->in, size.width, size.height);
            const std::vector<LodQuery>& rows = csv.queries;

            Context ctx = make_context(o->device);
            std::vector<float> levels(rows.size());
            if (!rows.empty()) {
              const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
              detail::OwnedBuffer qbuf(ctx, rows.size() * sizeof(LodQuery), usage, true);
              detail::OwnedBuffer lbuf(ctx, rows.size() * sizeof(float), usage, true);
              auto* q = static_cast<LodQuery*>(qbuf.mapped());
              std::memcpy(q, rows.data(), rows.size() * sizeof(LodQuery));
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
            std::string text;
            if (!csv.header.empty()) text += csv.header + ",lod\n";
            char num[32];
            for (size_t i = 0; i < rows.size(); ++i) {
              std::snprintf(num, sizeof num, "%.6f", double(levels[i]));
              text += csv.rows[i];
              text += ',';
              text += num;
              text += '\n';
            }
            io::AtomicOutputs files;
            files.write(o->out, [&](const std::string& tmp) { io::write_text_file(tmp, text); });
            files.commit();
            std::printf("%zu queries on %s -> %s\n", rows.size(), ctx.info().name.c_str(), o->out.c_str());
          }};
}

}  // namespace glint::cli
