// pmr_fuzz_seeds OUT: writes the crafted seed inputs of the fuzz targets (the files of issue 21 "Safe on
// files from strangers", at sizes that load quickly, and issue 31's lock files and posing bombs) into
// OUT/gltf, OUT/environment, OUT/calibration, OUT/sidecar, OUT/lock and OUT/posing. scripts/fuzz.sh adds the small models of the glTF sample corpus when it is present.
// The fuzzer mutates these into the full-size cases (counts, dimensions and indices are numbers in them).
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <ImfRgbaFile.h>

#include "fuzz/sidecar_reference.h"
#include "gltf_builder.h"

namespace fs = std::filesystem;
using namespace pmr::test;

namespace {

void save(const fs::path& path, const std::vector<uint8_t>& bytes) {
  fs::create_directories(path.parent_path());
  write_bytes(path, bytes);
}

void save(const fs::path& path, const std::string& text) { save(path, std::vector<uint8_t>(text.begin(), text.end())); }

// A PNG header claiming w x h (IHDR, an empty IDAT, IEND): the decoder reads the size before any pixel.
std::vector<uint8_t> png_header(uint32_t w, uint32_t h, int color_type, int depth) {
  std::vector<uint8_t> png = make_png(1, 1, color_type, depth, std::vector<uint8_t>(8, 0));
  const size_t ihdr = 16;  // signature, length, "IHDR"
  for (int s = 0; s < 4; ++s)
    png[ihdr + size_t(s)] = uint8_t(w >> (24 - 8 * s)), png[ihdr + 4 + size_t(s)] = uint8_t(h >> (24 - 8 * s));
  const uint32_t crc = crc32(png.data() + 12, 17);
  for (int s = 0; s < 4; ++s) png[29 + size_t(s)] = uint8_t(crc >> (24 - 8 * s));
  return png;
}

// A baseline JPEG's start claiming w x h: SOI, a quantization table, the frame header, EOI.
std::vector<uint8_t> jpeg_header(uint16_t w, uint16_t h) {
  std::vector<uint8_t> j = {0xff, 0xd8, 0xff, 0xdb, 0x00, 0x43, 0x00};
  j.insert(j.end(), 64, 1);
  j.insert(j.end(), {0xff, 0xc0, 0x00, 0x0b, 0x08, uint8_t(h >> 8), uint8_t(h), uint8_t(w >> 8), uint8_t(w), 0x01, 0x01,
                     0x11, 0x00, 0xff, 0xd9});
  return j;
}

// One triangle with TEXCOORD_0 and a base colour texture whose image is `image` (a JSON image object).
GltfFile textured_triangle(const nlohmann::json& image) {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
  const int uv = g.data<float>({0, 0, 1, 0, 0, 1}, kFloat, "VEC2");
  const int idx = g.data<uint16_t>({0, 1, 2}, kUShort, "SCALAR");
  g.mesh(nlohmann::json::array(
      {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"indices", idx}, {"material", 0}}}));
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  g.add("textures", {{"source", 0}});
  g.add("images", image);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  return g;
}

// The triangle with its image in the GLB's buffer.
std::vector<uint8_t> glb_with_image(const std::vector<uint8_t>& image, const char* mime) {
  GltfFile g = textured_triangle(nlohmann::json::object());
  const int view = g.view(image);
  g.doc["images"][0] = {{"bufferView", view}, {"mimeType", mime}};
  return g.glb();
}

std::string text(const GltfFile& g, const std::string& buffer_uri) { return g.finished(buffer_uri).dump(); }

void gltf_seeds(const fs::path& out) {
  const std::vector<uint8_t> rgba(4 * 4 * 4, 200);
  const std::vector<uint8_t> png = make_png(4, 4, 6, 8, rgba);
  save(out / "textured.glb", glb_with_image(png, "image/png"));
  save(out / "png16_32768x16385.glb", glb_with_image(png_header(32768, 16385, 0, 16), "image/png"));
  save(out / "png_18918x18918.glb", glb_with_image(png_header(18918, 18918, 6, 8), "image/png"));
  save(out / "jpeg_23170x23170.glb", glb_with_image(jpeg_header(23170, 23170), "image/jpeg"));
  {  // external files: the fuzz target's folder holds tex.png and buf.bin
    GltfFile g = textured_triangle({{"uri", "tex.png"}});
    save(out / "external_image.gltf", text(g, "data:application/octet-stream;base64," + base64(g.bin)));
    nlohmann::json d = g.finished("buf.bin");
    d["buffers"][0]["byteLength"] = 256;
    save(out / "external_buffer.gltf", d.dump());
    for (const char* uri : {"../outside.bin", "..%2Foutside.bin", "../../../../../../etc/passwd", "/dev/zero", "."}) {
      d["buffers"][0]["uri"] = uri;
      save(out / ("buffer_uri_" + std::to_string(std::hash<std::string>()(uri) % 1000) + ".gltf"), d.dump());
    }
    GltfFile unused = textured_triangle({{"uri", "tex.png"}});
    unused.add("images", {{"uri", "../outside.png"}});
    save(out / "unused_image.gltf", text(unused, "data:application/octet-stream;base64," + base64(unused.bin)));
  }
  for (const char* mime : {"image/ktx2", "image/webp"}) {
    GltfFile g = textured_triangle({{"uri", std::string("data:") + mime + ";base64,AAAA"}});
    save(out / (std::string("data_uri_") + (mime + 6) + ".gltf"),
         text(g, "data:application/octet-stream;base64," + base64(g.bin)));
  }
  {  // morph targets all pointing at one implicit (bufferView-less, all zero) POSITION accessor
    GltfFile g;
    const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
    const int zero = g.accessor(-1, kFloat, "VEC3", 3);
    nlohmann::json targets = nlohmann::json::array();
    for (int t = 0; t < 16; ++t) targets.push_back({{"POSITION", zero}});
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", pos}}}, {"targets", targets}}}));
    g.doc["meshes"][0]["weights"] = std::vector<double>(16, 0.5);
    g.add("nodes", {{"mesh", 0}});
    g.scene({0});
    save(out / "morph_implicit.glb", g.glb());
  }
  {  // an implicit accessor instanced by many nodes
    GltfFile g;
    const int zero = g.accessor(-1, kFloat, "VEC3", 3 * 64);
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", zero}}}}}));
    std::vector<int> roots;
    for (int n = 0; n < 23; ++n) roots.push_back(g.add("nodes", {{"mesh", 0}}));
    g.scene(roots);
    save(out / "implicit_instanced.gltf", g.finished("").dump());
  }
  {  // animation samplers sharing one key accessor; a long translation animation
    GltfFile g;
    const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", pos}}}}}));
    g.add("nodes", {{"mesh", 0}});
    g.scene({0});
    const int times = g.data<float>({0, 41666}, kFloat, "SCALAR");
    const int moves = g.data<float>({0, 0, 0, 1, 0, 0}, kFloat, "VEC3");
    nlohmann::json samplers = nlohmann::json::array(), channels = nlohmann::json::array();
    for (int s = 0; s < 8; ++s) {
      samplers.push_back({{"input", times}, {"output", moves}});
      channels.push_back({{"sampler", s}, {"target", {{"node", 0}, {"path", "translation"}}}});
    }
    g.add("animations", {{"samplers", samplers}, {"channels", channels}, {"name", "long"}});
    save(out / "animation_shared_keys.glb", g.glb());
  }
  {  // index fields of 2^32, names with escape sequences, an extras array
    GltfFile g;
    const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", pos}}}}}));
    g.add("nodes", {{"mesh", 0},
                    {"name",
                     "\x1b]0;title\x07\xc2\x9b"
                     "2J"}});
    g.scene({0});
    nlohmann::json d = g.finished("data:application/octet-stream;base64," + base64(g.bin));
    d["asset"]["generator"] = "\x1b[2Kpmr: all good";
    d["extras"] = std::vector<int>(64, 7);
    save(out / "escape_names.gltf", d.dump());
    d["nodes"][0]["mesh"] = uint64_t(1) << 32;
    save(out / "index_2_32.gltf", d.dump());
  }
  {  // a skinned, animated node with a camera, a spot light with a radius and a rect light
    GltfFile g;
    const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
    const int joints = g.data<uint16_t>({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, kUShort, "VEC4");
    const int weights = g.data<float>({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, kFloat, "VEC4");
    const int ibm = g.data<float>({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, kFloat, "MAT4");
    g.mesh(
        nlohmann::json::array({{{"attributes", {{"POSITION", pos}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}}}}));
    g.add("nodes", {{"mesh", 0}, {"skin", 0}});
    g.add("nodes", {{"name", "joint"}, {"rotation", {0, 0, 0, 1}}});
    g.add("nodes", {{"camera", 0},
                    {"translation", {0, 0, 3}},
                    {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}, {"EXT_lights_area", {{"light", 0}}}}}});
    g.add("skins", {{"joints", {1}}, {"inverseBindMatrices", ibm}});
    g.add("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}});
    g.doc["extensionsUsed"] = {"KHR_lights_punctual", "EXT_lights_area"};
    g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "spot"}, {"intensity", 2}, {"extras", {{"pmr_radius", 0.1}}}}};
    g.doc["extensions"]["EXT_lights_area"]["lights"] = {
        {{"type", "rect"}, {"intensity", 20}, {"size", 0.5}, {"rect", {{"aspect", 2}}}}};
    const int times = g.data<float>({0, 1}, kFloat, "SCALAR");
    const int rot = g.data<float>({0, 0, 0, 1, 0, 1, 0, 0}, kFloat, "VEC4");
    g.add("animations", {{"samplers", {{{"input", times}, {"output", rot}, {"interpolation", "LINEAR"}}}},
                         {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}}}}});
    g.scene({0, 1, 2});
    save(out / "skin_camera_light.glb", g.glb());
  }
}

// A Radiance .hdr of w x h, flat RGBE (rle = false) or new-style run-length encoded scanlines.
std::vector<uint8_t> hdr(int w, int h, bool rle) {
  std::string head =
      "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " + std::to_string(w) + "\n";
  std::vector<uint8_t> out(head.begin(), head.end());
  for (int y = 0; y < h; ++y) {
    if (rle) {
      out.insert(out.end(), {2, 2, uint8_t(w >> 8), uint8_t(w)});
      for (int c = 0; c < 4; ++c) {  // each channel as one run
        out.push_back(uint8_t(128 + w));
        out.push_back(uint8_t(c == 3 ? 128 : 64 + 16 * c + y));
      }
    } else {
      for (int x = 0; x < w; ++x) out.insert(out.end(), {uint8_t(100 + x), uint8_t(50 + y), 80, 128});
    }
  }
  return out;
}

void environment_seeds(const fs::path& out) {
  fs::create_directories(out);
  save(out / "flat.hdr", hdr(4, 2, false));
  save(out / "rle.hdr", hdr(16, 4, true));
  std::vector<uint8_t> huge = hdr(16, 1, true);
  const std::string claim = "-Y 1 +X 16";
  std::string big = "-Y 32768 +X 65535";
  std::string all(huge.begin(), huge.end());
  all.replace(all.find(claim), claim.size(), big);
  save(out / "claims_huge.hdr", std::vector<uint8_t>(all.begin(), all.end()));
  const int w = 8, h = 4;
  std::vector<Imf::Rgba> px(size_t(w * h));
  for (int i = 0; i < w * h; ++i) px[size_t(i)] = Imf::Rgba(half(0.1f * float(i)), half(0.5f), half(1.0f), half(1.0f));
  for (const auto& [name, channels, compression] :
       {std::tuple{"rgb_zip.exr", Imf::WRITE_RGB, Imf::ZIP_COMPRESSION},
        std::tuple{"y_none.exr", Imf::WRITE_Y, Imf::NO_COMPRESSION},
        std::tuple{"rgb_piz.exr", Imf::WRITE_RGB, Imf::PIZ_COMPRESSION},
        std::tuple{"rgba_rle.exr", Imf::WRITE_RGBA, Imf::RLE_COMPRESSION}}) {
    Imf::RgbaOutputFile file((out / name).c_str(), w, h, channels, 1, Imath::V2f(0, 0), 1, Imf::INCREASING_Y,
                             compression);
    file.setFrameBuffer(px.data(), 1, size_t(w));
    file.writePixels(h);
  }
}

void calibration_seeds(const fs::path& out) {
  const std::string portrait = R"({"configVersion": "3.0", "serial": "LKG-P01234", "pitch": {"value": 52.1},
    "slope": {"value": -7.1}, "center": {"value": 0.56}, "DPI": {"value": 324}, "screenW": {"value": 1536},
    "screenH": {"value": 2048}, "viewCone": {"value": 40}, "flipImageX": {"value": 0}, "flipImageY": {"value": 0},
    "flipSubp": {"value": 0}, "invView": {"value": 1}, "fringe": {"value": 0}, "verticalAngle": {"value": 0}})";
  save(out / "portrait.json", portrait);
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = portrait;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  save(out / "dpi_1e-300.json", with(R"("DPI": {"value": 324})", R"("DPI": {"value": 1e-300})"));
  save(out / "slope_tiny.json", with(R"("slope": {"value": -7.1})", R"("slope": {"value": 1e-300})"));
  save(out / "center_huge.json", with(R"("center": {"value": 0.56})", R"("center": {"value": 1e300})"));
  save(out / "unknown_serial_flipped.json",
       with(R"("serial": "LKG-P01234")", R"("serial": "XYZ", "flipImageX": 1, "flipSubp": 1)"));
  save(out / "gen3_cells.json",
       with(R"("serial": "LKG-P01234",)", R"("serial": "LKG-L01234", "CellPatternMode": {"value": 3},
    "subpixelCells": [{"ROffsetX": 0.1, "ROffsetY": 0, "GOffsetX": 0.4, "GOffsetY": 0, "BOffsetX": 0.7, "BOffsetY": 0},
                      {"ROffsetX": 0.7, "ROffsetY": 0.5, "GOffsetX": 0.4, "GOffsetY": 0.5, "BOffsetX": 0.1, "BOffsetY": 0.5}],)"));
}

void sidecar_seeds(const fs::path& out) {
  const std::string frame0 = pmr::fuzz::reference_sidecar(0);
  save(out / "frame0.json", frame0);
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = frame0;
    const size_t at = s.find(from);
    if (at == std::string::npos) throw pmr::Error("sidecar seed: '" + from + "' not in the reference sidecar");
    s.replace(at, from.size(), to);
    return s;
  };
  save(out / "output_absolute.json", with("\"frame_0000.exr\"", "\"/etc/passwd\""));
  save(out / "output_parent.json", with("\"frame_0000.exr\"", "\"../frame_0000.exr\""));
  save(out / "fps_0.json", with("\"fps\": 24", "\"fps\": 0"));
  save(out / "frame_huge.json", with("\"frame\": 0", "\"frame\": 1e308"));
  // what once crashed or stalled the readers (issue 48): a value nested 100,000 deep, an object of
  // 20,000 keys (quadratic parsing took seconds at that size; 200,000 parse in linear time but take the
  // sanitized target longer than its 5 s timeout), names recorded byte-exact in hex
  save(out / "deep.json", with("\"pmr-sidecar-1\"", std::string(100000, '[') + std::string(100000, ']')));
  std::string keys = "{";
  for (int k = 0; k < 20000; ++k) keys += (k ? ",\"" : "\"") + std::to_string(k) + "\":0";
  save(out / "many_keys.json", with("\"frame\": 0", "\"frame\": 0, \"extra\": " + keys + "}"));
  save(out / "outputs_hex.json", with("\"outputs\": {", "\"outputs_hex\": {\"encoded\": \"fffe2e657872\"}, \"outputs\": {"));
  save(out / "scene_hex.json", with("\"scene\": ", "\"scene_hex\": \"2e2e2f6574632f706173737764\", \"scene\": "));
}

// A lock file's text is a sidecar: this run's configuration, another one's, and text that is none.
void lock_seeds(const fs::path& out) {
  const std::string frame0 = pmr::fuzz::reference_sidecar(0);
  save(out / "same.json", frame0);
  std::string other = frame0;
  other.replace(other.find("\"fps\": 24"), 9, "\"fps\": 30");
  save(out / "other_fps.json", other);
  save(out / "empty", std::string());
  save(out / "not_json", std::string("pmr lock"));
}

// Small versions of issue 31's posing bombs (each names a node, skin and animation the fuzzer can
// grow): morph targets sharing one accessor with animated weights, a chain of nodes whose root moves,
// a skin of chained joints.
void posing_seeds(const fs::path& out) {
  auto moving = [](GltfFile& g, int node, const char* path, const std::vector<float>& values, const char* type) {
    const int in = g.data<float>({0.0f, 2.0f}, kFloat, "SCALAR");
    g.doc["accessors"][size_t(in)]["min"] = {0.0};
    g.doc["accessors"][size_t(in)]["max"] = {2.0};
    const int v = g.data<float>(values, kFloat, type);
    g.add("animations",
          {{"samplers", nlohmann::json::array({{{"input", in}, {"output", v}}})},
           {"channels", nlohmann::json::array({{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}})}});
  };
  auto triangle = [] {
    GltfFile g;
    const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", pos}}}}}));
    g.add("nodes", {{"mesh", 0}});
    g.scene({0});
    return g;
  };
  GltfFile morph = triangle();
  const int delta = morph.data<float>({0, 0, 1, 0, 0, 1, 0, 0, 1}, kFloat, "VEC3");
  for (int k = 0; k < 20; ++k) morph.doc["meshes"][0]["primitives"][0]["targets"].push_back({{"POSITION", delta}});
  moving(morph, 0, "weights", std::vector<float>(40, 0.25f), "SCALAR");
  save(out / "morph.glb", morph.glb());
  GltfFile chain = triangle();
  chain.doc["scenes"][0]["nodes"] = {1};
  for (int n = 1; n <= 50; ++n)
    chain.add("nodes", n < 50 ? nlohmann::json{{"children", {n + 1}}} : nlohmann::json{{"children", {0}}});
  moving(chain, 1, "translation", {0, 0, 0, 1, 0, 0}, "VEC3");
  save(out / "chain.glb", chain.glb());
  GltfFile skin = triangle();
  auto& attributes = skin.doc["meshes"][0]["primitives"][0]["attributes"];
  attributes["JOINTS_0"] = skin.data<uint16_t>({0, 0, 0, 0, 1, 0, 0, 0, 19, 0, 0, 0}, kUShort, "VEC4");
  attributes["WEIGHTS_0"] = skin.data<float>({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, kFloat, "VEC4");
  skin.doc["nodes"][0]["skin"] = 0;
  nlohmann::json joints = nlohmann::json::array();
  for (int n = 1; n <= 20; ++n) {
    skin.add("nodes", n < 20 ? nlohmann::json{{"children", {n + 1}}} : nlohmann::json::object());
    joints.push_back(n);
  }
  skin.add("skins", {{"joints", joints}});
  skin.doc["scenes"][0]["nodes"] = {0, 1};
  moving(skin, 1, "rotation", {0, 0, 0, 1, 0, 0.7071f, 0, 0.7071f}, "VEC4");
  save(out / "skin.glb", skin.glb());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: pmr_fuzz_seeds OUT_DIR\n");
    return 2;
  }
  const fs::path out = argv[1];
  try {
    gltf_seeds(out / "gltf");
    environment_seeds(out / "environment");
    calibration_seeds(out / "calibration");
    sidecar_seeds(out / "sidecar");
    lock_seeds(out / "lock");
    posing_seeds(out / "posing");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmr_fuzz_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
