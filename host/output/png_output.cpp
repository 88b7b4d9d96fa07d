// PNG previews through libpng: 8-bit sRGB, written row by row into an AtomicFile.
#include <png.h>

#include <Imath/half.h>

#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>

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

}  // namespace

void write_png_preview(const std::string& path, int width, int height, const uint16_t* rgba_half, double pixel_aspect,
                       bool opaque) {
  if (width < 1 || height < 1 || !rgba_half) throw Error("cannot write " + path + ": empty image");
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
  AtomicFile file(path);
  FILE* f = std::fopen(file.temp_path().c_str(), "wb");
  if (!f) throw Error("cannot write " + path + ": " + write_failure(errno));
  PngError err;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const size_t channels = opaque ? 3 : 4;
  std::vector<uint8_t> row(size_t(width) * channels);
  bool ok = png && info;
  if (ok && setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, f);
    png_set_compression_level(png, 1);
    png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8,
                 opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    if (pixel_aspect != 1.0) {
      // pixels per unit along x and y: a pixel is 1 / x wide and 1 / y tall, so y / x is its aspect
      const double y = std::lround(100000.0 * pixel_aspect);
      if (!(y >= 1.0 && y <= 2147483647.0)) throw Error("cannot write " + path + ": pixel aspect out of range");
      png_set_pHYs(png, info, 100000, png_uint_32(y), PNG_RESOLUTION_UNKNOWN);
    }
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) {
      const uint16_t* src = rgba_half + size_t(y) * size_t(width) * 4;
      for (size_t x = 0; x < size_t(width); ++x) {
        if (opaque) {  // what a panel shows over black: the premultiplied colour as it is
          for (int c = 0; c < 3; ++c) row[3 * x + size_t(c)] = lut[src[4 * x + size_t(c)]];
        } else {
          straight_pixel(src + 4 * x, lut, &row[4 * x]);
        }
      }
      png_write_row(png, row.data());
    }
    png_write_end(png, info);
  } else {
    ok = false;
  }
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
