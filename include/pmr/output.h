// The data products (DESIGN section 6): EXR images, the multi-part views EXR and the JSON sidecar.
// Every writer writes to a temporary file in the destination folder and renames it into place once the
// file is complete, so a failed or interrupted run never leaves a partial file under the final name.
// All errors are pmr::Error with one line naming the file.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pmr/quilt.h"
#include "pmr/rig.h"
#include "pmr/scene.h"

namespace pmr {

enum class ExrCompression { None, Zip, ZipFast, Piz, Rle };
// "none", "zip", "zip-fast" (ZIP through a faster encoder), "piz", "rle" (lower case, as the CLI documents); pmr::Error otherwise.
ExrCompression parse_exr_compression(const std::string& name);
// The inverse of parse_exr_compression.
const char* to_string(ExrCompression c);

// Ensures the directory exists (creating it and its parents) and is writable (creates and removes a
// probe file). Throws pmr::Error "cannot write to output folder X: <reason>". Call it before long work.
void prepare_output_dir(const std::string& dir);
// What prepare_output_dir can tell without creating anything: throws the same pmr::Error when `dir` is
// empty, exists and is not a folder, or lies below something that is not a folder. For a check before
// the inputs are read.
void check_output_dir(const std::string& dir);
// The longest file name an AtomicFile can write: NAME_MAX (255 bytes) less what its temporary name adds.
size_t max_output_file_name();

// A file written under a temporary name in the same folder as `final_path` and renamed into place by
// commit(). The constructor creates the (empty) temporary file, so an unwritable or missing folder
// fails early with pmr::Error. The destructor removes the temporary if commit() was not reached.
// commit() replaces an existing file at final_path atomically (POSIX rename); it does not fsync.
class AtomicFile {
 public:
  explicit AtomicFile(std::string final_path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& final_path() const { return final_path_; }
  const std::string& temp_path() const { return temp_path_; }
  bool committed() const { return committed_; }
  // Renames the temporary to the final path. Throws pmr::Error on failure (the temporary is then
  // still removed by the destructor). Every stream writing the temporary must be closed before.
  void commit();

 private:
  std::string final_path_, temp_path_;
  bool committed_ = false;
  int slot_ = -1;  // registration with the interrupt handler (output/interrupt.h)
};

// Writes `text` to `path` through an AtomicFile. Throws pmr::Error naming the file (and the reason:
// a full disk shows here) on failure.
void write_text_atomic(const std::string& path, const std::string& text);

// What an EXR written for a frame records in its header besides the pixels (docs/OUTPUTS.md; built by
// host/output/exr_metadata.cpp): the frame's place in the sequence, its sidecar, and the rig whose
// per-view matrices become worldToCamera / worldToNDC.
enum class ExrImage { Encoded, Views, Quilt };
struct ExrMetadata {
  long frame = 0;
  double time = 0.0;  // seconds: frame / fps, as the sidecar records it
  double fps = 24.0;
  std::string sidecar;  // the sidecar's file name (in the same folder)
  Rig rig;              // this frame's rig (an animated camera moves it)
  int center_view = 0;  // the view whose matrices the encoded image and the quilt carry
  QuiltLayout quilt;    // the quilt's layout (its worldToNDC lands in the center view's tile)
};

// Half RGBA EXR (scanline, one part), row 0 at the top (data window (0,0)-(width-1,height-1)).
// rgba_half: width*height*4 uint16 (IEEE half bits), row-major, RGBA, read in place (no copy).
// threads > 0 sets OpenEXR's global thread count used for compression (Imf::setGlobalThreadCount).
// depth (optional, [y][x] floats) adds a FLOAT channel "Z"; pixel_aspect is the header's
// pixelAspectRatio (a quilt of non-square view pixels). meta (optional) adds the frame's attributes for
// an image of kind `image` (Encoded or Quilt). subpixel_alpha (optional, [y][x][3] halves) adds the
// half channels AR, AG, AB: OpenEXR's per-channel alpha, each colour channel's own coverage (the
// encoded image: each subpixel's; docs/OUTPUTS.md).
void write_rgba_exr(const std::string& path, int width, int height, const uint16_t* rgba_half, ExrCompression c,
                    int threads = 0, const float* depth = nullptr, float pixel_aspect = 1.0f,
                    const ExrMetadata* meta = nullptr, ExrImage image = ExrImage::Encoded,
                    const uint16_t* subpixel_alpha = nullptr);

// The name of part i of a views file with `views` parts: view_000, view_001, ... with 3 digits, or as
// many as views - 1 needs (view_0000 .. view_1000 for 1001 views) so names sort in view order.
std::string view_part_name(int i, int views);

// Multi-part EXR: one scanline part per view, named by view_part_name, each half RGBA width x height.
// volume: [view][y][x][4] halves, contiguous, row 0 at the top. If depth != nullptr each part also gets
// a FLOAT channel "Z" from depth [view][y][x]. pixel_aspect is stored as each part's pixelAspectRatio
// (a view raster's pixels are not square when its aspect differs from the display's: pass
// A * height / width so that viewers show the views undistorted; 1 = square pixels). meta (optional)
// adds the frame's attributes to every part, each with its own view's `view` name and matrices;
// meta->rig.views must equal `views`.
void write_views_exr(const std::string& path, int width, int height, int views, const uint16_t* volume,
                     const float* depth, ExrCompression c, int threads = 0, float pixel_aspect = 1.0f,
                     const ExrMetadata* meta = nullptr);

// True when the EXR file opens and every part has all its pixel data (a truncated file is not
// complete). Throws only std::bad_alloc: running out of memory says nothing about the file.
bool exr_is_complete(const std::string& path);

// The quick check of an EXR file, without decoding a pixel: every part's header reads, its chunk table
// is complete, and every chunk lies inside the file, after the header, at the scanline the table puts it,
// with a packed size no larger than its unpacked one, none overlapping another. "" when it holds, else
// what does not. Never throws.
std::string exr_chunk_problem(const std::string& path);

// Readers (used by the tests). They return the data window's size and the pixels row 0 at the top,
// RGBA half bits; a missing alpha channel reads as 1.0, missing colour channels as 0.
void read_rgba_exr(const std::string& path, int& width, int& height, std::vector<uint16_t>& rgba_half);
// Names of all parts of a (single- or multi-part) EXR file; "" for a part without a name.
std::vector<std::string> read_exr_part_names(const std::string& path);
// Pixels of part `part` (0-based). If depth != nullptr it receives the part's "Z" channel as floats
// ([y][x]), or is cleared if the part has no "Z" channel.
void read_views_exr_part(const std::string& path, int part, int& width, int& height, std::vector<uint16_t>& rgba_half,
                         std::vector<float>* depth = nullptr);

// An 8-bit sRGB PNG for a person to look at: the linear half RGBA values (row 0 at the top, colour
// premultiplied by alpha) as PNG's straight alpha: colour divided by alpha where 0 < alpha < 1, encoded
// with the sRGB transfer curve, clamped to [0, 1] and rounded; alpha linear. Written atomically, fast deflate
// (a preview, not an archive). A pixel_aspect (pixel width / height) other than 1 is recorded in a pHYs
// chunk. `opaque`: RGB only, what the pixels show over black. The encoded image is previewed so: its
// three subpixels come from three views, so no one alpha per pixel composites it right (a viewer would
// darken covered subpixels next to empty ones), while the display shows it over black.
void write_png_preview(const std::string& path, int width, int height, const uint16_t* rgba_half,
                       double pixel_aspect = 1.0, bool opaque = false);
// The image resampled to square pixels (most viewers ignore a PNG's pixel aspect): stretched along one
// axis, never shrunk (width x pixel_aspect when > 1, else height / pixel_aspect), bilinear in linear
// light on the premultiplied values, edges clamped. Unchanged when the size stays.
std::vector<uint16_t> square_pixels(const uint16_t* rgba_half, int width, int height, double pixel_aspect,
                                    int& out_width, int& out_height);
// Reads an 8-bit RGBA (or RGB, gray: expanded) PNG, row 0 at the top (for the tests).
void read_png_rgba8(const std::string& path, int& width, int& height, std::vector<uint8_t>& rgba);
// The sRGB transfer curve (IEC 61966-2-1) of a linear value, clamped to [0, 1].
double srgb_encode(double linear);

// A file the frame wrote, as its sidecar records it: name, size and checksum (output/checksum.h), so
// that --resume and `pmr verify` can check the frame without decoding it.
struct OutputChecksum {
  std::string file;
  uint64_t bytes = 0;
  std::string checksum;
};

// What the sidecar records besides the rig and the display.
struct SidecarInfo {
  std::string scene;  // the scene file as given (empty = the bundled default scene)
  int frame = 0;
  std::string method = "pmr";       // "pmr" or the baseline's name
  std::string sampling = "view";    // "view" or "subpixel" (docs/SAMPLING.md)
  std::string shading = "lambert";  // "lambert" or "pbr" (docs/SHADING.md)
  double exposure_ev = 0.0;
  double environment_intensity = 1.0;  // pbr: scales the uniform environment
  std::vector<SceneLight> lights;      // pbr: the frame's lights as used (FrameRenderer::Frame::lights)
  int tile_x = 16, tile_y = 2, tile_v = 16;
  int camera = -1;          // glTF camera index, -1 = the default framing of the bounding sphere
  bool has_bounds = false;  // world bounds of the scene the default framing used
  glm::dvec3 bounds_lo{0.0}, bounds_hi{0.0};
  std::string compression;  // EXR compression of the images ("" = not recorded)
  // Files written for this frame, as (kind, file name) pairs, e.g. {"encoded", "frame_0000.exr"}.
  std::vector<std::pair<std::string, std::string>> outputs;
  std::vector<OutputChecksum> output_checksums;  // of the written outputs (the sidecar is written last)
  std::vector<std::string> warnings;             // e.g. "near plane raised ..."
  // The frame's place in a sequence (DESIGN section 7), so any frame can be reproduced alone.
  double time = 0.0;  // seconds: frame / fps
  double fps = 24.0;
  int animation = -1;          // glTF animation index, -1 none, -2 all
  std::string animation_name;  // its name ("all" for every animation)
  bool turntable = false;
  double turntable_deg = 0.0;  // DEG:FRAMES as requested
  long turntable_frames = 0;
  double turntable_angle = 0.0;                             // this frame's angle, degrees
  glm::dvec3 pivot{0.0};                                    // the turntable axis passes through it (along +Y)
  int quilt_columns = 0, quilt_rows = 0;                    // of the quilt output (0: none)
  int center_view = -1;                                     // the view of the center preview (-1: none)
  bool depth = false;                                       // Z channels in the views / quilt files
  std::string display_source;                               // "preset NAME" or "calibration FILE"
  std::vector<std::pair<std::string, double>> calibration;  // the calibration file's values, as read
  std::string calibration_serial;
  // Checksums of what the render read (output/checksum.h; "" = not recorded): the scene file, every
  // other file the loader read (path relative to the scene's folder, checksum), the --display-config
  // file. The program version is always recorded (pmr::program_version()).
  std::string scene_checksum;
  std::vector<std::pair<std::string, std::string>> scene_files;
  std::string display_config_checksum;
  // pbr: the environment image (--environment as given, "" = the uniform default), its checksum and
  // rotation (its intensity is environment_intensity)
  std::string environment_file, environment_checksum;
  double environment_rotation_deg = 0.0;
  bool allow_outside_scene_folder = false;  // --allow-outside-scene-folder: recorded only when given
  std::vector<double> background;           // --background as linear R, G, B, A; empty: transparent (not recorded)
};

// The sidecar's JSON text (pretty printed, doubles with round-trip precision).
std::string sidecar_json(const Rig& rig, const Display& display, const SidecarInfo& info);
// Compares the configuration that decides a frame's pixels (scene, method, tile, camera, display, rig,
// framing, fps, animation, turntable, shading and its lights; not the frame, its time or the outputs) of
// two sidecars' JSON texts. The lights' positions and directions follow the frame (animation, turntable):
// they are compared only between sidecars of the same frame. Returns "" when they agree, else the first differing key (or "unreadable" when `existing` does
// not parse).
// With ignore_scene_derived, the keys that follow from the scene file's content (scene_bounds, the
// turntable's pivot, the animation's name, the lights) are not compared: for a frame known to come from another
// scene (sidecar_provenance), only the configuration the user chose matters.
std::string sidecar_config_difference(const std::string& existing, const std::string& expected,
                                      bool ignore_scene_derived = false);

// Where a sidecar's frame came from. Never throws: a damaged or old sidecar gives empty strings.
struct SidecarProvenance {
  // The scene's identity: the checksum algorithm, the scene file's and every other read file's
  // checksums as one canonical string; "" when the sidecar records none (written before pmr recorded
  // them, or damaged). Two frames with equal non-empty identities were rendered from the same bytes.
  std::string scene;
  std::string version;  // program_version, "" when absent
};
SidecarProvenance sidecar_provenance(const std::string& sidecar_text);

// Writes the JSON sidecar (DESIGN section 6) atomically. Matrices are 16 numbers, column-major.
void write_sidecar(const std::string& path, const Rig& rig, const Display& display, const SidecarInfo& info);

}  // namespace pmr
