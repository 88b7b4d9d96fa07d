// PNG previews through libpng: 8-bit sRGB, written row by row into an AtomicFile.
#include <png.h>

#include <Imath/half.h>

#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include "output/view_transform.h"
#include "pmr/error.h"
#include "pmr/output.h"

namespace pmr {

double srgb_encode(double x) {
  if (!(x > 0.0)) return 0.0;  // also NaN
  if (x >= 1.0) return 1.0;
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

namespace {

// libpng reports errors through longjmp; the message is kept for one clear line.
struct PngError {
  char message[256] = "";
};

void on_error(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof e->message, "%s", msg);
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

uint8_t to_byte(double v) { return uint8_t(std::lround(std::min(1.0, std::max(0.0, v)) * 255.0)); }

// One RGBA pixel of premultiplied halves as straight 8-bit sRGB: PNG's alpha is straight, so a partly
// covered pixel's colour is divided by its coverage before the curve (else every edge darkens into a
// fringe). Whole coverage (the common case) goes through the table of every half value.
void straight_pixel(const uint16_t* src, const std::vector<uint8_t>& lut, uint8_t* out) {
  half a;
  a.setBits(src[3]);
  const double alpha = double(float(a));
  out[3] = to_byte(alpha);
  for (int c = 0; c < 3; ++c) {
    if (alpha > 0.0 && alpha < 1.0) {
      half v;
      v.setBits(src[c]);
      out[c] = to_byte(srgb_encode(double(float(v)) / alpha));
    } else {
      out[c] = lut[src[c]];
    }
  }
}

// One row through a view transform other than Standard: halves -> straight (or over black, opaque)
// floats -> the transform -> clipped bytes.
void transformed_row(const uint16_t* src, size_t width, bool opaque, const ViewTransform& transform,
                     std::vector<float>& scratch, uint8_t* out) {
  scratch.resize(width * 4);
  for (size_t x = 0; x < width; ++x) {
    half h[4];
    for (int c = 0; c < 4; ++c) h[c].setBits(src[4 * x + size_t(c)]);
    const float a = float(h[3]), unpremultiply = !opaque && a > 0.0f && a < 1.0f ? 1.0f / a : 1.0f;
    for (int c = 0; c < 3; ++c) scratch[4 * x + size_t(c)] = float(h[c]) * unpremultiply;
    scratch[4 * x + 3] = a;
  }
  transform.apply(scratch.data(), width);
  const size_t channels = opaque ? 3 : 4;
  for (size_t x = 0; x < width; ++x)
    for (size_t c = 0; c < channels; ++c) out[channels * x + c] = to_byte(double(scratch[4 * x + c]));
}

}  // namespace

namespace {

// What write_rows writes: the image and how its colour becomes bytes.
struct PngRows {
  const uint16_t* pixels;
  int width, height;
  png_uint_32 aspect_y;  // pHYs y per 100000 x; 0: square pixels, no chunk
  bool opaque;
  const ViewTransform* transform;  // null: Standard through `lut`
  const std::vector<uint8_t>* lut;
};

// The libpng calls between setjmp and the end of the image; false after a libpng error (longjmp).
// Kept apart so that nothing the caller holds lives across the setjmp.
bool write_rows(png_structp png, png_infop info, FILE* f, const PngRows& job) {
  const size_t width = size_t(job.width), channels = job.opaque ? 3 : 4;
  std::vector<uint8_t> row(width * channels);
  std::vector<float> scratch;
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_init_io(png, f);
  png_set_compression_level(png, 1);
  png_set_IHDR(png, info, png_uint_32(job.width), png_uint_32(job.height), 8,
               job.opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (!job.transform) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  // pixels per unit along x and y: a pixel is 1 / x wide and 1 / y tall, so y / x is its aspect
  if (job.aspect_y) png_set_pHYs(png, info, 100000, job.aspect_y, PNG_RESOLUTION_UNKNOWN);
  png_write_info(png, info);
  for (int y = 0; y < job.height; ++y) {
    const uint16_t* src = job.pixels + size_t(y) * width * 4;
    if (job.transform) {
      transformed_row(src, width, job.opaque, *job.transform, scratch, row.data());
    } else if (job.opaque) {  // what a panel shows over black: the premultiplied colour as it is
      for (size_t x = 0; x < width * 4; x += 4)
        for (size_t c = 0; c < 3; ++c) row[x / 4 * 3 + c] = (*job.lut)[src[x + c]];
    } else {
      for (size_t x = 0; x < width; ++x) straight_pixel(src + 4 * x, *job.lut, &row[4 * x]);
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, info);
  return true;
}

}  // namespace

void write_png_preview(const std::string& path, int width, int height, const uint16_t* rgba_half, double pixel_aspect,
                       bool opaque, const ViewTransform* transform) {
  if (width < 1 || height < 1 || !rgba_half) throw Error("cannot write " + path + ": empty image");
  const double aspect_y = pixel_aspect == 1.0 ? 0.0 : double(std::lround(100000.0 * pixel_aspect));
  if (pixel_aspect != 1.0 && !(aspect_y >= 1.0 && aspect_y <= 2147483647.0))
    throw Error("cannot write " + path + ": pixel aspect out of range");
  // sRGB lookup for every half value: the curve is applied once per distinct input, not per pixel
  static const std::vector<uint8_t> lut = [] {  // thread-safe initialization
    std::vector<uint8_t> t(65536);
    for (uint32_t h = 0; h < 65536; ++h) {
      half v;
      v.setBits(uint16_t(h));
      t[h] = to_byte(srgb_encode(double(float(v))));
    }
    return t;
  }();
  const PngRows job{rgba_half, width,
                    height,    png_uint_32(aspect_y),
                    opaque,    transform && !transform->is_standard() ? transform : nullptr,
                    &lut};
  AtomicFile file(path);
  FILE* f = std::fopen(file.temp_path().c_str(), "wb");
  if (!f) throw Error("cannot write " + path + ": " + write_failure(errno));
  PngError err;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const bool ok = png && info && write_rows(png, info, f, job);
  png_destroy_write_struct(png ? &png : nullptr, info ? &info : nullptr);
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed)
    throw Error("cannot write " + path + ": " +
                write_failure(err.message[0] ? std::string(err.message) : std::strerror(errno)));
  file.commit();
}

std::vector<uint16_t> square_pixels(const uint16_t* rgba_half, int width, int height, double pixel_aspect,
                                    int& out_width, int& out_height) {
  if (!(pixel_aspect > 0.0) || !std::isfinite(pixel_aspect)) throw Error("square_pixels: invalid pixel aspect");
  out_width = pixel_aspect > 1.0 ? int(std::lround(width * pixel_aspect)) : width;
  out_height = pixel_aspect < 1.0 ? int(std::lround(height / pixel_aspect)) : height;
  if (out_width == width && out_height == height)
    return std::vector<uint16_t>(rgba_half, rgba_half + size_t(width) * size_t(height) * 4);
  std::vector<uint16_t> out(size_t(out_width) * size_t(out_height) * 4);
  // source position of an output pixel center, its two neighbours and the weight of the second
  auto taps = [](int i, int n_out, int n_in, int& a, int& b, float& t) {
    const double s = std::max(0.0, (i + 0.5) * double(n_in) / double(n_out) - 0.5);
    a = std::min(int(s), n_in - 1);
    b = std::min(a + 1, n_in - 1);
    t = float(s - a);
  };
  auto at = [&](int x, int y, int c) {
    half v;
    v.setBits(rgba_half[(size_t(y) * size_t(width) + size_t(x)) * 4 + size_t(c)]);
    return float(v);
  };
  for (int y = 0; y < out_height; ++y) {
    int y0, y1;
    float ty;
    taps(y, out_height, height, y0, y1, ty);
    for (int x = 0; x < out_width; ++x) {
      int x0, x1;
      float tx;
      taps(x, out_width, width, x0, x1, tx);
      for (int c = 0; c < 4; ++c) {
        const float top = at(x0, y0, c) + tx * (at(x1, y0, c) - at(x0, y0, c));
        const float bottom = at(x0, y1, c) + tx * (at(x1, y1, c) - at(x0, y1, c));
        out[(size_t(y) * size_t(out_width) + size_t(x)) * 4 + size_t(c)] = half(top + ty * (bottom - top)).bits();
      }
    }
  }
  return out;
}

void read_png_rgba8(const std::string& path, int& width, int& height, std::vector<uint8_t>& rgba) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) throw Error("cannot read " + path + ": " + image.message);
  image.format = PNG_FORMAT_RGBA;
  rgba.assign(PNG_IMAGE_SIZE(image), 0);
  if (!png_image_finish_read(&image, nullptr, rgba.data(), 0, nullptr)) {
    png_image_free(&image);
    throw Error("cannot read " + path + ": " + image.message);
  }
  width = int(image.width), height = int(image.height);
}

}  // namespace pmr
