// The data products (DESIGN section 6): EXR images, the multi-part views EXR and PNG previews (the JSON
// sidecar: output/sidecar.h).
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

class ViewTransform;

enum class ExrCompression { None, Zip, ZipFast, Piz, Rle, Dwaa, Dwab };
// "none", "zip", "zip-fast" (ZIP through a faster encoder), "piz", "rle", "dwaa", "dwab" (lower case, as the
// CLI documents); pmr::Error otherwise. DWAA and DWAB are lossy for the half R, G and B channels only (the
// OpenEXR library's rule: A and the float Z stay lossless), at the library's default level 45.
ExrCompression parse_exr_compression(const std::string& name);
// The inverse of parse_exr_compression.
const char* to_string(ExrCompression c);
// Whether the compression loses data (DCT of R, G, B): refused for the encoded panel image, where
// neighbouring subpixels come from different views and ringing would become crosstalk.
bool is_lossy(ExrCompression c);

// Ensures the directory exists (creating it and its parents) and is writable (creates and removes a
// probe file). Throws pmr::Error "cannot write to output folder X: <reason>". Call it before long work.
// Returns whether it created the folder (a caller refused before writing removes it again).
bool prepare_output_dir(const std::string& dir);
// What prepare_output_dir can tell without creating anything: throws the same pmr::Error when `dir` is
// empty, exists and is not a folder, or lies below something that is not a folder. For a check before
// the inputs are read.
void check_output_dir(const std::string& dir);
// The longest file name an AtomicFile can write: NAME_MAX (255 bytes) less what its temporary name adds.
size_t max_output_file_name();

// Temporary names, for AtomicFile and the folder lock: "<dir>/.<name>.tmp-<host>-<pid>-<n>", hidden, in
// the destination's folder (so the rename stays on one file system). The host is gethostname's,
// limited to letters, digits, '.' and '-' (others become '_') and 32 bytes; n counts up per process.
std::string temporary_name(const std::string& final_path);
// Who left a temporary file, from its name (false: not a temporary name). Names from before the host
// was recorded (".<name>.tmp-<pid>-<n>") parse with an empty host.
struct TemporaryOwner {
  std::string host;
  long pid = 0;
  bool this_host = false;  // the host is this machine's
  bool running = false;    // this host's, and its process is alive (or not ours to signal)
};
bool parse_temporary_name(const std::string& file_name, TemporaryOwner& owner);
// Removes the temporary files in `dir` that this host's processes left and that no longer run (a
// SIGKILL); another host's are left alone, since the folder may be shared by nodes (NFS). Returns how
// many it removed.
size_t remove_dead_temporaries(const std::string& dir);

// A file written under a temporary name in the same folder as `final_path` and renamed into place by
// commit(). The constructor creates the (empty) temporary file, so an unwritable or missing folder
// fails early with pmr::Error. The destructor removes the temporary if commit() was not reached.
// commit() replaces an existing file at final_path atomically (POSIX rename); it does not fsync. Only
// a regular file is replaced: the constructor refuses a path holding a symbolic link, a folder, a FIFO
// or a device.
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

// A write's failure as a message: strerror(err) for an errno, or a library's message; a file-size limit
// (EFBIG: `ulimit -f`, SIGXFSZ being ignored) is named as such, whoever reported it.
std::string write_failure(int err);
std::string write_failure(const std::string& reason);

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
// `transform` (output/view_transform.h): the view transform in place of the sRGB curve (null = Standard);
// it applies to the straight colour, or to the colour over black when opaque. A managed transform's PNG
// carries no sRGB chunk: its display need not be sRGB.
void write_png_preview(const std::string& path, int width, int height, const uint16_t* rgba_half,
                       double pixel_aspect = 1.0, bool opaque = false, const ViewTransform* transform = nullptr);
// The image resampled to square pixels (most viewers ignore a PNG's pixel aspect): stretched along one
// axis, never shrunk (width x pixel_aspect when > 1, else height / pixel_aspect), bilinear in linear
// light on the premultiplied values, edges clamped. Unchanged when the size stays.
std::vector<uint16_t> square_pixels(const uint16_t* rgba_half, int width, int height, double pixel_aspect,
                                    int& out_width, int& out_height);
// Reads an 8-bit RGBA (or RGB, gray: expanded) PNG, row 0 at the top (for the tests).
void read_png_rgba8(const std::string& path, int& width, int& height, std::vector<uint8_t>& rgba);
// The sRGB transfer curve (IEC 61966-2-1) of a linear value, clamped to [0, 1].
double srgb_encode(double linear);

}  // namespace pmr
