#include "test_util.h"

#include <glm/gtc/matrix_transform.hpp>

#include <Imath/half.h>

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <cstdlib>

#include <memory>

namespace pmr::test {

const ClRuntime& runtime() {
  static std::unique_ptr<ClRuntime> rt(new ClRuntime());
  return *rt;
}

Scene empty_scene(bool double_sided) {
  Scene s;
  PmrMaterial m = default_material();
  m.double_sided = double_sided ? 1u : 0u;
  s.materials.push_back(m);
  return s;
}

void add_triangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material) {
  const uint32_t base = uint32_t(s.positions.size());
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  for (const glm::vec3& p : {a, b, c}) {
    s.positions.push_back(p);
    PmrVertexAttr at{};
    at.normal[0] = n.x, at.normal[1] = n.y, at.normal[2] = n.z;
    for (int k = 0; k < 4; ++k) at.color[k] = 1.0f;
    at.scale = 1.0f;
    s.attributes.push_back(at);
  }
  PmrTriangle t{};
  t.v[0] = base, t.v[1] = base + 1, t.v[2] = base + 2;
  t.material = material;
  t.face_normal[0] = n.x, t.face_normal[1] = n.y, t.face_normal[2] = n.z;
  t.has_normals = 1;
  s.triangles.push_back(t);
}

SceneTextureSlot& base_colour_texture(Scene& s, uint32_t material, int texture, int set) {
  while (s.material_inputs.size() < s.materials.size()) {
    const PmrMaterial& m = s.materials[s.material_inputs.size()];
    SceneMaterialInputs in;
    in.metallic = m.metallic, in.roughness = m.roughness, in.unlit = m.unlit != 0;
    for (int c = 0; c < 3; ++c) in.emissive[c] = m.emissive[c];
    in.slots[kSlotBaseColor].srgb = in.slots[kSlotEmissive].srgb = true;
    s.material_inputs.push_back(in);
  }
  SceneTextureSlot& slot = s.material_inputs[material].slots[kSlotBaseColor];
  slot.texture = texture, slot.texcoord = set;
  return slot;
}

glm::vec2& texcoord(Scene& s, int set, size_t v) {
  if (s.texcoords.size() <= size_t(set)) s.texcoords.resize(size_t(set) + 1);
  for (std::vector<glm::vec2>& t : s.texcoords) t.resize(s.positions.size(), glm::vec2(0.0f));
  return s.texcoords[size_t(set)][v];
}

Scene random_scene(int n, uint32_t seed, bool double_sided, float max_size) {
  Scene s = empty_scene(double_sided);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.002f, max_size);
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c(u(rng), u(rng), u(rng));
    const float r = size(rng);
    const glm::vec3 a = c + r * glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 b = c + r * glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 d = c + r * glm::vec3(u(rng), u(rng), u(rng));
    if (glm::length(glm::cross(b - a, d - a)) < 1e-7f) continue;
    add_triangle(s, a, b, d);
  }
  // keep the framing fixed: the scene bounds are always the unit box
  return s;
}

float half_value(uint16_t bits) {
  half h;
  h.setBits(bits);
  return float(h);
}

Rig sidecar_rig() {
  Rig rig;
  rig.views = 3;
  rig.view_w = 64;
  rig.view_h = 32;
  rig.yfov = glm::radians(40.0);
  rig.cone = glm::radians(30.0);
  rig.aspect = 166.0 / 93.0;
  rig.focal = 5.0;
  rig.near = 3.0;
  rig.near_eff = 3.5;
  rig.far = 8.0;
  rig.center_view = glm::lookAt(glm::dvec3(3.0, 2.0, 4.0), glm::dvec3(0.0, 0.5, 0.0), glm::dvec3(0.0, 1.0, 0.0));
  return rig;
}

Rig small_rig(int views, int w, int h, bool angular) {
  RigConfig rc;
  rc.views = views;
  rc.view_w = w;
  rc.view_h = h;
  rc.angular_spacing = angular;
  return make_rig(rc, Display{}, glm::dvec3(-1.0), glm::dvec3(1.0));
}

Rendered render(const Scene& scene, const Rig& rig, int tx, int ty, int tv, const Display* display,
                std::vector<uint16_t>* encoded) {
  PipelineConfig pc;
  pc.tile_x = tx, pc.tile_y = ty, pc.tile_v = tv;
  return render_with(scene, rig, pc, display, encoded);
}

Rendered render_with(const Scene& scene, const Rig& rig, PipelineConfig pc, const Display* display,
                     std::vector<uint16_t>* encoded) {
  pc.debug_outputs = true;
  Pipeline p(runtime(), pc);
  p.set_scene(scene);
  p.configure(rig, display);
  Rendered r;
  r.times = p.render(rig);
  p.read_debug(r.key, r.depth, r.count);
  p.read_volume(r.volume);
  r.mtas = p.read_mtas();
  if (encoded) p.read_display(*encoded);
  return r;
}

std::string corpus_dir() {
  const std::string d = std::string(PMR_SOURCE_DIR) + "/../shared/gltf";
  struct stat st;
  return stat(d.c_str(), &st) == 0 && S_ISDIR(st.st_mode) ? d : std::string();
}

std::vector<std::string> corpus_files(const std::string& dir) {
  std::vector<std::string> out;
  std::function<void(const std::string&)> walk = [&](const std::string& d) {
    DIR* h = opendir(d.c_str());
    if (!h) return;
    while (dirent* e = readdir(h)) {
      const std::string name = e->d_name;
      if (name == "." || name == "..") continue;
      const std::string path = d + "/" + name;
      struct stat st;
      if (stat(path.c_str(), &st) != 0) continue;
      if (S_ISDIR(st.st_mode)) walk(path);
      else if (name.size() > 5 && (name.substr(name.size() - 5) == ".gltf" || name.substr(name.size() - 4) == ".glb"))
        out.push_back(path);
    }
    closedir(h);
  };
  walk(dir);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace pmr::test

namespace pmr::test {

glm::vec3 focal_point(const Rig& rig, double x, double y) {
  const PmrParams P = make_params(rig);
  const double xv = (2.0 * x / rig.view_w - 1.0) * rig.focal / P.ndc_scale_x;
  const double yv = (1.0 - 2.0 * y / rig.view_h) * rig.focal / P.ndc_scale_y;
  const glm::dvec4 world = glm::inverse(rig.center_view) * glm::dvec4(xv, yv, -rig.focal, 1.0);
  return glm::vec3(world);
}

EncodedRender render_encoded(const Scene& scene, const Rig& rig, const Display& d, const PipelineConfig& pc) {
  Pipeline p(runtime(), pc);
  p.set_scene(scene);
  p.configure(rig, &d);
  p.render(rig);
  EncodedRender r;
  r.fused = p.fused();
  r.has_volume = p.has_volume();
  if (r.has_volume) p.read_volume(r.volume);
  p.read_display(r.image);
  return r;
}

std::unique_ptr<Pipeline> encoder_pipeline(const Display& display, int views, int vw, int vh) {
  RigConfig rc;
  rc.views = views, rc.view_w = vw, rc.view_h = vh;
  const Rig rig = make_rig(rc, display, glm::dvec3(-1), glm::dvec3(1));
  auto p = std::make_unique<Pipeline>(runtime(), PipelineConfig{});
  p->set_scene(random_scene(1, 1, false));
  p->configure(rig, &display);
  return p;
}

PmrParams params_for(const Rig& rig, int tx, int ty, int tv) {
  PmrParams P = make_params(rig);
  P.tiles_x = (rig.view_w + tx - 1) / tx;
  P.tiles_y = (rig.view_h + ty - 1) / ty;
  P.tiles_v = (rig.views + tv - 1) / tv;
  return P;
}

}  // namespace pmr::test

namespace pmr::test {

// The pmr runs of the tests see no $OCIO: a user's colour configuration must not change the previews
// the tests expect (docs/COLOUR.md).
const bool kOcioUnset = (::unsetenv("OCIO"), true);

CliRun run(const std::string& args) { return run_env("", args); }

pid_t start(const std::string& args, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string cmd = std::string(PMR_BINARY) + " " + args + " > '" + log + "' 2>&1";
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), (char*)nullptr);
    _exit(127);
  }
  return pid;
}

CliRun run_env(const std::string& env, const std::string& args) {
  return run_wrapped(env.empty() ? "" : "env " + env, args);
}

CliRun run_wrapped(const std::string& wrapper, const std::string& args) {
  const std::string cmd = (wrapper.empty() ? "" : wrapper + " ") + std::string(PMR_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pmr_cli_" + name + "_" + std::to_string(getpid());
  std::system(("rm -rf '" + d + "'").c_str());
  return d;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool exists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

size_t count_entries(const std::string& dir) {
  FILE* p = popen(("ls -A '" + dir + "' 2>/dev/null | wc -l").c_str(), "r");
  size_t n = 0;
  if (fscanf(p, "%zu", &n) != 1) n = 0;
  pclose(p);
  return n;
}

std::set<std::string> listing(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

void save_square_glb(const std::string& path) {
  Scene square = empty_scene(true);
  add_triangle(square, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0});
  add_triangle(square, {-1, -1, 0}, {1, 1, 0}, {-1, 1, 0});
  save_glb(square, path);
}

void expect_one_error_line(const CliRun& r, const std::string& fragment, int status) {
  EXPECT_EQ(r.status, status) << r.output;
  const auto at = r.output.find("pmr: error: ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string line = r.output.substr(at);
  EXPECT_EQ(line.find('\n'), line.size() - 1) << "exactly one error line: " << r.output;
  EXPECT_NE(line.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << line;
}

Rig subpixel_display_rig(Display& d) {
  d = Display{};
  d.width = 64, d.height = 40;
  d.lens_pitch = parse_rational("7.3125", "L");
  d.tan_slant = parse_rational("-0.15", "T");
  RigConfig rc;
  rc.views = 10, rc.view_w = 3 * d.width, rc.view_h = d.height;
  d.offset = default_offset(d.lens_pitch, rc.views);
  return make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
}

void expect_resume_compares(const std::string& options, const std::string& recorded, const std::string& key) {
  const std::string out = temp_dir("resume_" + key);
  const std::string small = " --views 4 --view-size 48x24 --display 160x90 --out " + out;
  ASSERT_EQ(run("render " + options + small).status, 0);
  EXPECT_NE(read_file(out + "/frame_0000.json").find(recorded), std::string::npos);
  EXPECT_EQ(run("render " + options + " --resume" + small).status, 0);
  expect_one_error_line(run("render --resume" + small), key + " differs");
}

}  // namespace pmr::test

namespace pmr::test {

std::vector<int> encoded_view_indices(const Display& display, int views, int view_w, int view_h) {
  RigConfig rc;
  rc.views = views, rc.view_w = view_w, rc.view_h = view_h;
  const Rig rig = make_rig(rc, display, glm::dvec3(-1), glm::dvec3(1));
  Pipeline p(runtime(), PipelineConfig{});
  p.set_scene(random_scene(1, 1, false));
  p.configure(rig, &display);
  const size_t plane = size_t(view_w) * view_h;
  std::vector<uint16_t> vol(plane * views * 4), enc;
  for (int v = 0; v < views; ++v) {
    const uint16_t h = half(float(v)).bits();
    for (size_t x = 0; x < plane * 4; ++x) vol[size_t(v) * plane * 4 + x] = h;
  }
  p.encode_volume(vol);
  p.read_display(enc);
  std::vector<int> out(size_t(display.width) * display.height * 3);
  for (size_t px = 0; px < size_t(display.width) * display.height; ++px)
    for (int k = 0; k < 3; ++k) {
      half h;
      h.setBits(enc[px * 4 + size_t(k)]);
      out[px * 3 + size_t(k)] = int(float(h));
    }
  return out;
}

std::vector<int> table_view_indices(const Display& display, int views) {
  const PmrEncodeParams p = make_encode_params(display, views, 1, 1);
  std::vector<PmrEncodeColumn> cols;
  std::vector<PmrEncodeRow> rows;
  make_encode_tables(display, p, cols, rows);
  std::vector<int> out(size_t(display.width) * display.height * 3);
  for (int i = 0; i < display.height; ++i)
    for (int s = 0; s < 3 * display.width; ++s) {
      const int cls = p.cell_rows > 1 ? (display.height - 1 - i) % p.cell_rows : 0;
      const PmrEncodeColumn& c = cols[size_t(cls) * 3 * display.width + size_t(s)];
      const PmrEncodeRow& r = rows[size_t(i)];
      int v = c.a_mod_n - r.q_mod_n - (c.b < r.s ? 1 : 0);
      v = (v + 2 * views) % views;
      if (display.reversed) v = views - 1 - v;
      out[size_t(i) * 3 * display.width + size_t(s)] = v;
    }
  return out;
}

}  // namespace pmr::test
