#include "pipeline/fine_stage.h"

#include <algorithm>

#include "pmr/error.h"

namespace pmr {

namespace {

// The volume form runs one work-item per 3D tile in groups of 8, which keeps the two cores balanced;
// the fused and subpixel forms run one work-item per group (their private state is large).
constexpr size_t kFineGroup = 8;

}  // namespace

FineStage::FineStage(Launcher& launcher, const ClProgram& program, const std::string& options, const int* tile)
    : launcher_(launcher),
      rt_(launcher.runtime()),
      options_(options),
      tile_{tile[0], tile[1], tile[2]},
      fine_(program, "fine_raster") {}

void FineStage::configure(const FinePaths& paths, int views, int view_w, int view_h, EncodeStage* encode) {
  paths_ = paths;
  const size_t voxels = size_t(views) * view_w * view_h;
  volume_bytes_ = voxels * 4 * sizeof(uint16_t);
  const size_t display_subpixels = encode ? size_t(3) * encode->params().display_w * encode->params().display_h : 0;
  debug_entries_ = !paths.debug ? 1 : (paths.volume ? voxels : display_subpixels) * size_t(paths.samples);
  const size_t vol = paths.volume ? volume_bytes_ : 0;
  const size_t disp = encode ? encode->display_bytes() / 4 * 7 : 0;  // RGBA and the subpixels' alpha
  const size_t dbg = paths.debug ? debug_entries_ * 12 : 0;
  if (vol + disp + dbg > rt_.global_mem_bytes())
    throw Error("the view volume (" + std::to_string(vol >> 20) + " MiB) and display image (" +
                std::to_string(disp >> 20) + " MiB) do not fit in the device's memory (" +
                std::to_string(rt_.global_mem_bytes() >> 20) + " MiB)");
  volume_ = rt_.buffer(std::max<size_t>(vol, 16), "view volume");
  dbg_key_ = rt_.buffer(debug_entries_ * 4, "debug keys");
  dbg_depth_ = rt_.buffer(debug_entries_ * 4, "debug depth");
  dbg_count_ = rt_.buffer(debug_entries_ * 4, "debug counts");
  if (paths.debug && !paths.volume) rt_.fill_zero(dbg_count_);  // the subpixel kernel keeps no counts
  blend_overflow_ = rt_.buffer(16, "BLEND overflow count");
  begin_frame();
  if (paths.fused) configure_fused(views, *encode);
  if (paths.subpixel) configure_subpixel(views, *encode);
}

// Tables of the fused form: the first subpixel of every view column and the first display row of every
// view row (the encoder's maps are monotone), and the column table as planes for 8-pixel vector loads:
// [field (a_mod_n, b, px)][subpixel k][pixel j].
void FineStage::configure_fused(int views, EncodeStage& encode) {
  if (fused_views_ != views) {
    fused_program_ = launcher_.build({"fine_encode.cl"}, options_ + " -DPMR_FUSED_VIEWS=" + std::to_string(views));
    fused_views_ = views;
    fine_encode_ = ClKernel(fused_program_, "fine_encode");
  }
  const TileOwnership own = encode.own_by_tiles(tile_[0]);
  column_start_ = rt_.upload(own.column_start, "fused column starts", kMinTableBytes);
  row_start_ = rt_.upload(own.row_start, "fused row starts", kMinTableBytes);
  const std::vector<PmrEncodeColumn>& columns = encode.columns();
  const size_t W = size_t(encode.params().display_w);
  std::vector<int32_t> soa(9 * W);
  for (size_t j = 0; j < W; ++j)
    for (size_t k = 0; k < 3; ++k) {
      const PmrEncodeColumn& c = columns[3 * j + k];
      soa[(0 + k) * W + j] = c.a_mod_n, soa[(3 + k) * W + j] = c.b, soa[(6 + k) * W + j] = c.px;
    }
  column_soa_ = rt_.upload(soa, "fused column planes", kMinTableBytes);
}

// The subpixel program (per view count: its private per-view arrays), the samples and the chunk list.
void FineStage::configure_subpixel(int views, EncodeStage& encode) {
  const int capacity = subpixel_chunk_capacity(views, paths_.samples);
  if (subpixel_views_ != views) {
    subpixel_program_ =
        launcher_.build({"fine_subpixel.cl"}, options_ + " -DPMR_SUBPIXEL_VIEWS=" + std::to_string(views) +
                                                  " -DPMR_SUBPIXEL_CAP=" + std::to_string(capacity) +
                                                  " -DPMR_SUBPIXEL_SLOTS=" + std::to_string(kSubpixelSlots));
    subpixel_views_ = views;
    fine_subpixel_ = ClKernel(subpixel_program_, "fine_subpixel");
  }
  const TileOwnership own = encode.own_by_tiles(tile_[0]);
  const std::vector<PmrEncodeColumn>& columns = encode.columns();
  // the column table's a_mod_n and b as planes, for 8-column vector loads (8 entries of slack at the end)
  std::vector<int32_t> a(columns.size() + 8), b(columns.size() + 8);
  for (size_t s = 0; s < columns.size(); ++s) a[s] = columns[s].a_mod_n, b[s] = columns[s].b;
  column_a_ = rt_.upload(a, "subpixel column views", kMinTableBytes);
  column_b_ = rt_.upload(b, "subpixel column ranks", kMinTableBytes);
  // the samples must lie in the view pixels the encoder tables name (tile ownership relies on it)
  const std::vector<int32_t> xs = subpixel_sample_columns(encode.params()), ys = subpixel_sample_rows(encode.params());
  for (size_t s = 0; s < xs.size(); ++s)
    if (xs[s] >> PMR_X_FRAC_BITS != columns[s].px) throw InternalError("subpixel sample outside its column");
  for (size_t i = 0; i < ys.size(); ++i)
    if (ys[i] >> PMR_Y_FRAC_BITS != encode.rows()[i].py) throw InternalError("subpixel sample outside its row");
  sample_x_ = rt_.upload(xs, "subpixel sample columns", kMinTableBytes);
  sample_y_ = rt_.upload(ys, "subpixel sample rows", kMinTableBytes);
  const std::vector<PmrSampleChunk> list = subpixel_chunks(own, tile_[0], tile_[1], capacity);
  num_chunks_ = uint32_t(list.size());
  chunks_ = rt_.upload(list, "subpixel chunks", kMinTableBytes);
}

void FineStage::run_volume(const SceneBuffers& scene, const GeometryStage& geometry, uint64_t num_tiles,
                           const ShadowBinding& shadows, const SourceBinding& source, FrameEvents& ev, const ClBuffer* out) {
  const cl_uint next = scene.bind_shading(fine_, geometry.params(), shadows, source);
  fine_.args_from(next, geometry.mtas(), geometry.tile_offsets(), geometry.tile_queue(), out ? *out : volume_, dbg_key_,
                  dbg_depth_, dbg_count_, blend_overflow_);
  ev.add(kFine, launcher_.launch(fine_, size_t(num_tiles), kFineGroup));
}

void FineStage::run_fused(const SceneBuffers& scene, const GeometryStage& geometry, size_t screen_tiles,
                          EncodeStage& encode, const ShadowBinding& shadows, const SourceBinding& source, FrameEvents& ev) {
  // the fused program is compiled without BLEND compositing (cl/fine_encode.cl)
  if (scene.blended()) throw InternalError("a scene with alphaMode BLEND on the fused path");
  const cl_uint next = scene.bind_shading(fine_encode_, geometry.params(), shadows, source);
  fine_encode_.args_from(next, geometry.mtas(), geometry.tile_offsets(), geometry.tile_queue(), encode.params_buffer(),
                         column_soa_, encode.rows_buffer(), column_start_, row_start_, encode.display(),
                         encode.sub_alpha());
  ev.add(kFine, launcher_.launch(fine_encode_, screen_tiles, 1));
  encode.straddle_alpha(ev);
}

void FineStage::run_subpixel(const SceneBuffers& scene, const GeometryStage& geometry, EncodeStage& encode,
                             const ShadowBinding& shadows, const SourceBinding& source, FrameEvents& ev) {
  const cl_uint next = scene.bind_shading(fine_subpixel_, geometry.params(), shadows, source);
  const bool debug = paths_.debug && !paths_.volume;  // per display subpixel
  fine_subpixel_.args_from(next, geometry.mtas(), geometry.tile_offsets(), geometry.tile_queue(),
                           encode.params_buffer(), column_a_, column_b_, encode.rows_buffer(), sample_x_, sample_y_,
                           chunks_, num_chunks_, encode.display(), encode.sub_alpha(), cl_uint(debug), dbg_key_,
                           dbg_depth_, blend_overflow_);
  ev.add(kFine, launcher_.launch(fine_subpixel_, num_chunks_, 1));
  encode.straddle_alpha(ev);
}

void FineStage::read_volume(std::vector<uint16_t>& out) const {
  if (!paths_.volume) throw InternalError("this configuration keeps no view volume");
  out.resize(volume_bytes_ / 2);
  rt_.read(volume_, out.data(), volume_bytes_);
}

void FineStage::read_debug(std::vector<uint32_t>& keys, std::vector<float>& depth, std::vector<uint32_t>& count) const {
  if (!paths_.debug) throw InternalError("debug outputs are off");
  keys.resize(debug_entries_);
  depth.resize(debug_entries_);
  count.resize(debug_entries_);
  rt_.read(dbg_key_, keys.data(), debug_entries_ * 4);
  rt_.read(dbg_depth_, depth.data(), debug_entries_ * 4);
  rt_.read(dbg_count_, count.data(), debug_entries_ * 4);
}

uint32_t FineStage::blend_overflow() const {
  uint32_t n = 0;
  rt_.read(blend_overflow_, &n, sizeof n);
  return n;
}

size_t FineStage::device_bytes() const {
  size_t total = 0;
  for (const ClBuffer* b : {&volume_, &dbg_key_, &dbg_depth_, &dbg_count_, &column_start_, &column_soa_, &row_start_,
                            &chunks_, &sample_x_, &sample_y_, &column_a_, &column_b_})
    total += b->size();
  return total;
}

}  // namespace pmr
