// EXR writers and readers: the encoded image (half RGBA) and the multi-part views file.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>
#include <ImfThreading.h>

#include <cmath>
#include <exception>
#include <limits>
#include <new>

#include "output/exr_metadata.h"
#include "output/exr_zip.h"
#include "pmr/error.h"
#include "pmr/output.h"

namespace pmr {
namespace {

static_assert(sizeof(Imf::Rgba) == 4 * sizeof(uint16_t), "Imf::Rgba must be four packed halves");
static_assert(sizeof(half) == sizeof(uint16_t), "half must be 16 bits");

// One line: OpenEXR messages may span lines and name the temporary file instead of the final one.
std::string clean_message(std::string msg, const std::string& temp, const std::string& final_path) {
  if (!temp.empty())
    for (size_t at = msg.find(temp); at != std::string::npos; at = msg.find(temp, at + final_path.size()))
      msg.replace(at, temp.size(), final_path);
  for (char& ch : msg)
    if (ch == '\n' || ch == '\r') ch = ' ';
  return msg;
}

// Runs f, turning OpenEXR / standard exceptions into pmr::Error("<verb> <path>: <reason>").
template <class F>
void guarded(const char* verb, const std::string& path, const std::string& temp, F&& f) {
  try {
    f();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // Iex::BaseExc derives from std::exception
    throw Error(std::string(verb) + " " + path + ": " + write_failure(clean_message(e.what(), temp, path)));
  } catch (...) {
    throw Error(std::string(verb) + " " + path + ": unknown error");
  }
}

Imf::Compression to_imf(ExrCompression c, const std::string& path) {
  switch (c) {
    case ExrCompression::None:
      return Imf::NO_COMPRESSION;
    case ExrCompression::Zip:
      return Imf::ZIP_COMPRESSION;
    case ExrCompression::ZipFast:
      return Imf::ZIP_COMPRESSION;
    case ExrCompression::Piz:
      return Imf::PIZ_COMPRESSION;
    case ExrCompression::Rle:
      return Imf::RLE_COMPRESSION;
    case ExrCompression::Dwaa:
      return Imf::DWAA_COMPRESSION;
    case ExrCompression::Dwab:
      return Imf::DWAB_COMPRESSION;
  }
  throw Error("cannot write " + path + ": invalid EXR compression value " + std::to_string(int(c)));
}

// The header's compression. zip and zip-fast are both ZIP; they differ in the encoder our writer uses
// (zip_encoder). Readers need nothing new: neither the encoder nor its level is stored in the file.
void set_compression(Imf::Header& h, ExrCompression c, const std::string& path) { h.compression() = to_imf(c, path); }

// What every image pmr writes shares: its compression, and its colour space stated (linear Rec. 709, D65
// white: OpenEXR's default Chromaticities), so readers need not assume it.
void start_header(Imf::Header& h, ExrCompression c, const std::string& path) {
  set_compression(h, c, path);
  Imf::addChromaticities(h, Imf::Chromaticities());
}

// OpenEXR's per-channel alpha names for R, G, B
const char* const kSubpixelAlpha[3] = {"AR", "AG", "AB"};

// zip: ISA-L and libdeflate at OpenEXR's level (exr_zip.h); zip-fast: ISA-L only, a third of zip's
// writer CPU for files about 10% larger
// (docs/SEQUENCES.md, "The ZIP writer").
ZipEncoder zip_encoder(ExrCompression c) {
  return c == ExrCompression::ZipFast ? ZipEncoder::Fast : ZipEncoder::Default;
}

void check_image(const std::string& path, int width, int height, int layers, const void* data) {
  if (width < 1 || height < 1 || layers < 1)
    throw Error("cannot write " + path + ": invalid image size " + std::to_string(width) + "x" +
                std::to_string(height) + (layers != 1 ? "x" + std::to_string(layers) : std::string()));
  if (!data) throw Error("cannot write " + path + ": no pixel data");
  // Element counts must fit size_t (and stay far from overflow when multiplied by 8 bytes).
  const double elems = double(width) * double(height) * double(layers) * 4.0;
  if (elems * 8.0 > double(std::numeric_limits<size_t>::max()) / 2.0)
    throw Error("cannot write " + path + ": image too large");
}

void set_threads(int threads) {
  if (threads > 0 && threads != Imf::globalThreadCount()) Imf::setGlobalThreadCount(threads);
}

void insert_half_rgba(Imf::FrameBuffer& fb, const uint16_t* pixels, int width) {
  char* base = const_cast<char*>(reinterpret_cast<const char*>(pixels));  // OpenEXR only reads it
  const size_t xs = 4 * sizeof(uint16_t), ys = xs * size_t(width);
  fb.insert("R", Imf::Slice(Imf::HALF, base + 0 * sizeof(uint16_t), xs, ys));
  fb.insert("G", Imf::Slice(Imf::HALF, base + 1 * sizeof(uint16_t), xs, ys));
  fb.insert("B", Imf::Slice(Imf::HALF, base + 2 * sizeof(uint16_t), xs, ys));
  fb.insert("A", Imf::Slice(Imf::HALF, base + 3 * sizeof(uint16_t), xs, ys));
}

// The header channels R, G, B, A (half) and, with `depth`, Z (float), with their pixels for the ZIP
// writer: interleaved half RGBA and a plane of floats, row 0 = EXR's top scanline.
ExrZipPart zip_rgba_part(Imf::Header header, const uint16_t* pixels, const float* depth, int width) {
  ExrZipPart part{std::move(header), {}};
  const char* base = reinterpret_cast<const char*>(pixels);
  const size_t xs = 4 * sizeof(uint16_t), ys = xs * size_t(width);
  const char* const names[4] = {"R", "G", "B", "A"};
  for (int k = 0; k < 4; ++k) {
    part.header.channels().insert(names[k], Imf::Channel(Imf::HALF));
    part.channels.push_back({names[k], base + k * sizeof(uint16_t), xs, ys});
  }
  if (depth) {
    part.header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    part.channels.push_back({"Z", reinterpret_cast<const char*>(depth), sizeof(float), sizeof(float) * size_t(width)});
  }
  return part;
}

void check_read_size(const std::string& path, const Imath::Box2i& dw, int& width, int& height) {
  const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
  if (w < 1 || h < 1 || w > (1 << 20) || h > (1 << 20) || w * h > (int64_t(1) << 32))
    throw Error("cannot read " + path + ": unsupported data window size " + std::to_string(w) + "x" +
                std::to_string(h));
  width = int(w);
  height = int(h);
}

}  // namespace

ExrCompression parse_exr_compression(const std::string& name) {
  if (name == "none") return ExrCompression::None;
  if (name == "zip") return ExrCompression::Zip;
  if (name == "zip-fast") return ExrCompression::ZipFast;
  if (name == "piz") return ExrCompression::Piz;
  if (name == "rle") return ExrCompression::Rle;
  if (name == "dwaa") return ExrCompression::Dwaa;
  if (name == "dwab") return ExrCompression::Dwab;
  throw Error("invalid EXR compression '" + name + "': expected none, zip, zip-fast, piz, rle, dwaa or dwab");
}

const char* to_string(ExrCompression c) {
  switch (c) {
    case ExrCompression::None:
      return "none";
    case ExrCompression::Zip:
      return "zip";
    case ExrCompression::ZipFast:
      return "zip-fast";
    case ExrCompression::Piz:
      return "piz";
    case ExrCompression::Rle:
      return "rle";
    case ExrCompression::Dwaa:
      return "dwaa";
    case ExrCompression::Dwab:
      return "dwab";
  }
  return "invalid";
}

bool is_lossy(ExrCompression c) { return c == ExrCompression::Dwaa || c == ExrCompression::Dwab; }

std::string view_part_name(int i, int views) {
  int digits = 3;
  for (int64_t limit = 1000; int64_t(views) - 1 >= limit; limit *= 10) ++digits;
  std::string num = std::to_string(i);
  if (int(num.size()) < digits) num.insert(0, size_t(digits) - num.size(), '0');
  return "view_" + num;
}

void write_rgba_exr(const std::string& path, int width, int height, const uint16_t* rgba_half, ExrCompression c,
                    int threads, const float* depth, float pixel_aspect, const ExrMetadata* meta, ExrImage image,
                    const uint16_t* subpixel_alpha) {
  check_image(path, width, height, 1, rgba_half);
  if (!(pixel_aspect > 0.0f) || !std::isfinite(pixel_aspect))
    throw Error("cannot write " + path + ": invalid pixel aspect ratio " + std::to_string(pixel_aspect));
  AtomicFile file(path);
  guarded("cannot write", path, file.temp_path(), [&] {
    set_threads(threads);
    // display and data window (0,0)-(w-1,h-1), INCREASING_Y
    Imf::Header header(width, height, pixel_aspect);
    start_header(header, c, path);
    if (meta) add_exr_metadata(header, *meta, image, meta->center_view);
    if (c == ExrCompression::Zip || c == ExrCompression::ZipFast) {  // our own chunk writer (exr_zip.h)
      ExrZipPart part = zip_rgba_part(header, rgba_half, depth, width);
      if (subpixel_alpha) {
        const char* sa = reinterpret_cast<const char*>(subpixel_alpha);
        const size_t sx = 3 * sizeof(uint16_t), sy = sx * size_t(width);
        for (int k = 0; k < 3; ++k) {
          part.header.channels().insert(kSubpixelAlpha[k], Imf::Channel(Imf::HALF));
          part.channels.push_back({kSubpixelAlpha[k], sa + 2 * k, sx, sy});
        }
      }
      write_zip_exr(file.temp_path(), path, {part}, zip_encoder(c), threads);
      return;
    }
    if (depth || subpixel_alpha) {  // half RGBA plus Z or AR, AG, AB: the general interface
      for (const char* ch : {"R", "G", "B", "A"}) header.channels().insert(ch, Imf::Channel(Imf::HALF));
      Imf::FrameBuffer fb;
      insert_half_rgba(fb, rgba_half, width);
      if (depth) {
        header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
        char* z = const_cast<char*>(reinterpret_cast<const char*>(depth));
        fb.insert("Z", Imf::Slice(Imf::FLOAT, z, sizeof(float), sizeof(float) * size_t(width)));
      }
      if (subpixel_alpha) {
        char* sa = const_cast<char*>(reinterpret_cast<const char*>(subpixel_alpha));
        for (int k = 0; k < 3; ++k) {
          header.channels().insert(kSubpixelAlpha[k], Imf::Channel(Imf::HALF));
          fb.insert(kSubpixelAlpha[k],
                    Imf::Slice(Imf::HALF, sa + 2 * k, 3 * sizeof(uint16_t), 3 * sizeof(uint16_t) * size_t(width)));
        }
      }
      Imf::OutputFile out(file.temp_path().c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(height);
      return;
    }
    Imf::RgbaOutputFile out(file.temp_path().c_str(), header, Imf::WRITE_RGBA);
    // Pixel (x, y) at base + x + y * width: the caller's memory, row 0 = EXR's top scanline.
    out.setFrameBuffer(reinterpret_cast<const Imf::Rgba*>(rgba_half), 1, size_t(width));
    out.writePixels(height);
  });  // the file is closed here
  file.commit();
}

void write_views_exr(const std::string& path, int width, int height, int views, const uint16_t* volume,
                     const float* depth, ExrCompression c, int threads, float pixel_aspect, const ExrMetadata* meta) {
  check_image(path, width, height, views, volume);
  if (meta && meta->rig.views != views)
    throw Error("cannot write " + path + ": the metadata's rig has " + std::to_string(meta->rig.views) +
                " views, the file " + std::to_string(views));
  if (!(pixel_aspect > 0.0f) || !std::isfinite(pixel_aspect))
    throw Error("cannot write " + path + ": invalid pixel aspect ratio " + std::to_string(pixel_aspect));
  AtomicFile file(path);
  guarded("cannot write", path, file.temp_path(), [&] {
    set_threads(threads);
    const size_t plane = size_t(width) * size_t(height);
    std::vector<Imf::Header> headers;
    headers.reserve(size_t(views));
    for (int i = 0; i < views; ++i) {
      Imf::Header h(width, height, pixel_aspect);
      start_header(h, c, path);
      h.setName(view_part_name(i, views));
      h.setType(Imf::SCANLINEIMAGE);
      if (meta) add_exr_metadata(h, *meta, ExrImage::Views, i);
      headers.push_back(std::move(h));
    }
    if (c == ExrCompression::Zip || c == ExrCompression::ZipFast) {  // our own chunk writer (exr_zip.h)
      std::vector<ExrZipPart> parts;
      parts.reserve(size_t(views));
      for (int i = 0; i < views; ++i)
        parts.push_back(zip_rgba_part(std::move(headers[size_t(i)]), volume + size_t(i) * plane * 4,
                                      depth ? depth + size_t(i) * plane : nullptr, width));
      write_zip_exr(file.temp_path(), path, parts, zip_encoder(c), threads);
      return;
    }
    for (Imf::Header& h : headers) {
      for (const char* ch : {"R", "G", "B", "A"}) h.channels().insert(ch, Imf::Channel(Imf::HALF));
      if (depth) h.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    }
    Imf::MultiPartOutputFile out(file.temp_path().c_str(), headers.data(), views);
    for (int i = 0; i < views; ++i) {
      Imf::OutputPart part(out, i);
      Imf::FrameBuffer fb;
      insert_half_rgba(fb, volume + size_t(i) * plane * 4, width);
      if (depth) {
        char* z = const_cast<char*>(reinterpret_cast<const char*>(depth + size_t(i) * plane));
        fb.insert("Z", Imf::Slice(Imf::FLOAT, z, sizeof(float), sizeof(float) * size_t(width)));
      }
      part.setFrameBuffer(fb);
      part.writePixels(height);
    }
  });
  file.commit();
}

bool exr_is_complete(const std::string& path) {
  try {
    Imf::MultiPartInputFile in(path.c_str());
    for (int p = 0; p < in.parts(); ++p) {
      Imf::InputPart part(in, p);
      if (!part.isComplete()) return false;
      // isComplete() only reads the offset table: decode every chunk too (every line into one scratch
      // line per channel: y stride 0), so that a file cut short or damaged in its data is caught.
      const Imath::Box2i dw = part.header().dataWindow();
      const size_t width = size_t(int64_t(dw.max.x) - dw.min.x + 1);
      size_t channels = 0;
      for (auto c = part.header().channels().begin(); c != part.header().channels().end(); ++c) ++channels;
      std::vector<float> scratch(width * channels);
      Imf::FrameBuffer fb;
      size_t k = 0;
      for (auto c = part.header().channels().begin(); c != part.header().channels().end(); ++c, ++k) {
        char* line = reinterpret_cast<char*>(scratch.data() + k * width) - size_t(dw.min.x) * sizeof(float);
        fb.insert(c.name(), Imf::Slice(Imf::FLOAT, line, sizeof(float), 0));
      }
      part.setFrameBuffer(fb);
      part.readPixels(dw.min.y, dw.max.y);
    }
    return in.parts() > 0;
  } catch (const std::bad_alloc&) {
    throw;  // out of memory is not an incomplete file
  } catch (...) {
    return false;
  }
}

void read_rgba_exr(const std::string& path, int& width, int& height, std::vector<uint16_t>& rgba_half) {
  guarded("cannot read", path, "", [&] {
    Imf::RgbaInputFile in(path.c_str());
    const Imath::Box2i dw = in.dataWindow();
    check_read_size(path, dw, width, height);
    rgba_half.assign(size_t(width) * size_t(height) * 4, 0);
    Imf::Rgba* pixels = reinterpret_cast<Imf::Rgba*>(rgba_half.data());
    in.setFrameBuffer(Imf::ComputeBasePointer(pixels, dw), 1, size_t(width));
    in.readPixels(dw.min.y, dw.max.y);
  });
}

std::vector<std::string> read_exr_part_names(const std::string& path) {
  std::vector<std::string> names;
  guarded("cannot read", path, "", [&] {
    Imf::MultiPartInputFile in(path.c_str());
    for (int i = 0; i < in.parts(); ++i) names.push_back(in.header(i).hasName() ? in.header(i).name() : std::string());
  });
  return names;
}

void read_views_exr_part(const std::string& path, int part, int& width, int& height, std::vector<uint16_t>& rgba_half,
                         std::vector<float>* depth) {
  guarded("cannot read", path, "", [&] {
    Imf::MultiPartInputFile file(path.c_str());
    if (part < 0 || part >= file.parts())
      throw Error("cannot read " + path + ": no part " + std::to_string(part) + " (the file has " +
                  std::to_string(file.parts()) + ")");
    Imf::InputPart in(file, part);
    const Imf::Header& header = in.header();
    const Imath::Box2i dw = header.dataWindow();
    check_read_size(path, dw, width, height);
    rgba_half.assign(size_t(width) * size_t(height) * 4, 0);
    Imf::FrameBuffer fb;
    const size_t xs = 4 * sizeof(uint16_t), ys = xs * size_t(width);
    const char* names[4] = {"R", "G", "B", "A"};
    for (int k = 0; k < 4; ++k)
      fb.insert(names[k], Imf::Slice::Make(Imf::HALF, rgba_half.data() + k, dw, xs, ys, 1, 1, k == 3 ? 1.0 : 0.0));
    if (depth) {
      if (header.channels().findChannel("Z")) {
        depth->assign(size_t(width) * size_t(height), 0.0f);
        fb.insert("Z", Imf::Slice::Make(Imf::FLOAT, depth->data(), dw, sizeof(float), sizeof(float) * size_t(width)));
      } else {
        depth->clear();
      }
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  });
}

}  // namespace pmr
