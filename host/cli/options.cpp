#include "cli/options.h"

#include <cerrno>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <cstdlib>
#include <sstream>

#include "cli/option_table.h"
#include "pmr/error.h"
#include "pmr/limits.h"
#include "pmr/rig.h"
#include "pmr/shared.h"

namespace pmr {

namespace {

double parse_double(const std::string& text, const std::string& opt) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v))
    throw Error("invalid " + opt + " '" + text + "': expected a number");
  return v;
}

}  // namespace

double parse_exposure(const std::string& text) {
  const double ev = parse_double(text, "--exposure");
  if (ev < -64.0 || ev > 64.0) throw Error("invalid --exposure '" + text + "': expected EV from -64 to 64");
  return ev;
}

double parse_environment_intensity(const std::string& text) {
  const double x = parse_double(text, "--environment-intensity");
  if (x < 0.0 || x > 1e6) throw Error("invalid --environment-intensity '" + text + "': expected 0 to 1e6");
  return x;
}

double parse_environment_rotation(const std::string& text) {
  return parse_double(text, "--environment-rotation");  // any finite angle
}

EnvironmentSource parse_environment(const std::string& text) { return EnvironmentSource::parse(text); }

void check_environment_options(const EnvironmentSource& source, bool given, bool rotation_given, Shading shading,
                               std::vector<std::string>& warnings) {
  if (given && shading != Shading::Pbr) throw Error("--environment lights the pbr model only: add --shading pbr");
  if (rotation_given && shading != Shading::Pbr)
    warnings.push_back("--environment-rotation turns the pbr model's environment: with --shading " +
                       std::string(to_string(shading)) + " it does nothing");
  else if (rotation_given && source.kind == EnvironmentSource::Kind::Uniform)
    warnings.push_back(
        "--environment-rotation does nothing to the uniform environment: it is the same in every "
        "direction");
}

namespace {

int parse_int(const std::string& text, const std::string& opt, int lo, int hi) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < lo || v > hi)
    throw Error("invalid " + opt + " '" + text + "': expected an integer in " + std::to_string(lo) + ".." +
                std::to_string(hi));
  return int(v);
}

// "WxH" or "XxYxV".
std::vector<int> parse_dims(const std::string& text, const std::string& opt, size_t count, int hi) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, 'x')) out.push_back(parse_int(part, opt, 1, hi));
  if (out.size() != count || text.back() == 'x')
    throw Error("invalid " + opt + " '" + text + "': expected " + (count == 2 ? "WxH" : "XxYxV"));
  return out;
}

}  // namespace

int parse_samples(const std::string& text) {
  const int samples = parse_int(text, "--samples", 1, 16);
  PmrParams P{};
  set_sample_pattern(samples, P);  // refuses all but 1, 4, 8 and 16
  return samples;
}

std::vector<int> parse_samples_list(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string w;
  while (std::getline(ss, w, ',')) out.push_back(parse_samples(w));
  if (out.empty()) out.push_back(parse_samples(text));  // "" is refused there
  return out;
}

namespace {

// The rig a Looking Glass panel's serial prefix recommends (the preset of that model, whose default
// sampling `subpixel` receives), or 48 views of the panel's aspect for an unknown one.
RigConfig rig_for_serial(const LookingGlassCalibration& c, std::string& quilt, bool& subpixel) {
  const std::pair<const char*, const char*> models[] = {
      {"LKG-P", "lg-portrait"}, {"LKG-E", "lg-go"},          {"LKG-J", "lg-16"},      {"LKG-H", "lg-16-portrait"},
      {"LKG-L", "lg-32"},       {"LKG-K", "lg-32-portrait"}, {"LKG-A", "lg-16-gen2"}, {"LKG-B", "lg-32-gen2"}};
  for (const auto& [prefix, preset] : models)
    if (c.serial.rfind(prefix, 0) == 0) {
      const DisplayPreset& p = find_display_preset(preset);
      quilt = p.quilt;
      subpixel = p.subpixel_sampling;
      RigConfig r = p.rig;
      r.cone_deg = c.view_cone;
      return r;
    }
  RigConfig r;
  r.views = 48;
  r.view_h = 560;
  r.view_w = std::max(1, int(std::lround(560.0 * c.screen_w / c.screen_h)));
  r.cone_deg = c.view_cone;
  return r;
}

// --preset and --display-config set the defaults that every other option then overrides.
void apply_display_source(RenderOptions& o, const std::vector<std::string>& args) {
  for (size_t i = 0; i + 1 < args.size(); ++i)  // the calibration file is read under the file-bytes budget
    if (args[i] == "--limit") as_usage([&] { parse_limits(args[i + 1], o.job.input_limits); });
  for (size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--preset") {
      if (args[i + 1] == "help") {
        o.preset_help = true;
        return;
      }
      const DisplayPreset& p = as_usage([&]() -> const DisplayPreset& { return find_display_preset(args[i + 1]); });
      o.job.display = p.display;
      o.offset_given = p.name != "paper-8k";  // a panel's offset comes from its calibration
      o.job.rig = p.rig;
      o.job.rig.angular_spacing = p.name != "paper-8k";  // Looking Glass software spaces its cameras angularly
      o.job.pipeline.sampling = p.subpixel_sampling ? Sampling::Subpixel : Sampling::View;
      o.job.display_source.name = "preset " + p.name;
      o.job.quilt_preview_opaque = p.name != "paper-8k";  // Looking Glass tools show quilts opaque
    } else if (args[i] == "--display-config") {
      const LookingGlassCalibration& c = o.job.display_source.calibration.emplace(
          read_looking_glass_calibration(args[i + 1], &o.job.warnings, o.job.input_limits.file_bytes));
      o.job.display = display_from_calibration(c);
      o.offset_given = true;  // the calibration's center decides it
      std::string quilt;
      bool subpixel = false;
      o.job.rig = rig_for_serial(c, quilt, subpixel);
      o.job.rig.angular_spacing = true;
      o.job.pipeline.sampling = subpixel ? Sampling::Subpixel : Sampling::View;
      o.job.display_source.name = "calibration " + args[i + 1];
      o.job.quilt_preview_opaque = true;
    }
  }
  int sources = 0;
  for (const std::string& a : args) sources += a == "--preset" || a == "--display-config";
  if (sources > 1) throw UsageError("give one of --preset and --display-config, once");
}

// The options of `pmr render`, in the order --help lists them (cli/option_table.h).
using RenderSection = OptionSection<RenderOptions>;

void set_frames(RenderOptions& o, const std::string& v, const std::string&) { o.job.frames = v; }

// --preset and --display-config are applied before every other option (apply_display_source).
void applied_first(RenderOptions&, const std::string&, const std::string&) {}

// The view transform's options, marked as given on the command line.
ViewTransformOptions& set_view(RenderOptions& o) {
  o.job.view_transform_given = true;
  return o.job.view_transform;
}

// Whether the panel PNG goes through a transform that needs every view's colour (an OpenColorIO one).
bool previews_need_views(const RenderOptions& o) {
  const char* env = std::getenv("OCIO");
  const bool managed = !o.job.view_transform.config.empty() || (env && *env);
  return managed && o.job.products.preview && o.job.products.encoded;
}

void set_write(RenderOptions& o, const std::string& v, const std::string&) {
  o.job.products.encoded = o.job.products.views = o.job.products.quilt = o.job.products.depth = false;
  std::stringstream ss(v);
  std::string w;
  while (std::getline(ss, w, ',')) {
    if (w == "encoded") o.job.products.encoded = true;
    else if (w == "views") o.job.products.views = true;
    else if (w == "quilt") o.job.products.quilt = true;
    else if (w == "depth") o.job.products.depth = true;
    else throw Error("invalid --write '" + w + "': expected a list of encoded, views, quilt, depth");
  }
  if (!o.job.products.encoded && !o.job.products.views && !o.job.products.quilt)
    throw Error("invalid --write: nothing to write (depth is a channel of views or quilt)");
  if (o.job.products.depth && !o.job.products.views && !o.job.products.quilt)
    throw Error("invalid --write: depth is a channel of the views or quilt EXR: add views or quilt");
}

const RenderSection kOutputOptions = {
    "output:",
    {
        {"--help", "-h", nullptr, "",  // not listed: the help itself
         [](RenderOptions& o, const std::string&, const std::string&) { o.help = true; }},
        {"--out", "-o", "DIR", "output folder (created if missing; default: out)",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.products.out_dir = v; }},
        {"--write", nullptr, "LIST",
         "any of encoded, views, quilt, depth (default: encoded). DIR/frame_NNNN.exr is\n"
         "the encoded image (half RGBA), DIR/frame_NNNN.views.exr one part per view,\n"
         "DIR/frame_NNNN_qsCxRaA.exr the views as a Looking Glass quilt (view 0 bottom\n"
         "left; in a sequence DIR/frame_qsCxRaA_NNNN.exr, see --name), depth a float\n"
         "Z channel (view-space depth, --depth-empty where empty) in the views and quilt\n"
         "files;\n"
         "DIR/frame_NNNN.json (rig, display, every view's matrices) is always written",
         set_write},
        {"--depth-empty", nullptr, "inf|Z",
         "depth where nothing was drawn (default inf, +infinity; Cycles writes 1e10,\n"
         "which keeps compositing arithmetic such as 0 x Z finite)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           if (v == "inf") return void(o.job.products.depth_empty = std::numeric_limits<float>::infinity());
           const double z = parse_double(v, name);
           if (!(z > 0.0 && z <= 3.0e38))
             throw Error("invalid " + name + " '" + v + "': expected inf or 0 < Z <= 3e38");
           o.job.products.depth_empty = float(z);
         }},
        {"--quilt", nullptr, "CxR", "quilt layout in tiles (default: the most square layout, e.g. 8x6 for 48)",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.quilt_layout = v; }},
        {"--preview", nullptr, nullptr,
         "also 8-bit sRGB PNGs: the encoded image, the center view (N / 2; stretched to\n"
         "square pixels, as a view's pixels span the display's aspect) and the quilt\n"
         "(tiles as rendered; their pixel aspect in the PNG's pHYs chunk)",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.products.preview = true; }},
        {"--ocio", nullptr, "CONFIG",
         "the previews' colour management: an OpenColorIO config (default: $OCIO when\n"
         "set; without one, Standard: the sRGB curve, clipped). EXRs stay scene-linear",
         [](RenderOptions& o, const std::string& v, const std::string&) { set_view(o).config = v; }},
        {"--display-device", nullptr, "NAME", "the config's display device (default: its default display)",
         [](RenderOptions& o, const std::string& v, const std::string&) { set_view(o).display = v; }},
        {"--view", nullptr, "NAME", "the display's view transform, e.g. Filmic (default: the display's default)",
         [](RenderOptions& o, const std::string& v, const std::string&) { set_view(o).view = v; }},
        {"--look", nullptr, "NAME", "a look of the config, e.g. 'Filmic - High Contrast' (default: none)",
         [](RenderOptions& o, const std::string& v, const std::string&) { set_view(o).look = v; }},
        {"--colorspace", nullptr, "NAME",
         "the config's name for pmr's pixels, linear Rec. 709 (default: its scene_linear\n"
         "role; name another when that role is not linear Rec. 709, e.g. ACEScg)",
         [](RenderOptions& o, const std::string& v, const std::string&) { set_view(o).colorspace = v; }},
        {"--view-exposure", nullptr, "EV",
         "the previews' exposure (Blender's View exposure: x 2^EV before the view, not\n"
         "in the EXRs; --exposure scales the render itself)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           set_view(o).exposure = parse_double(v, name);
         }},
        {"--view-gamma", nullptr, "G", "the previews' gamma (Blender's View gamma: ^(1 / G) after the display)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           set_view(o).gamma = parse_double(v, name);
         }},
        {"--name", nullptr, "PATTERN",
         "file stem (default frame_%04d); the frame number as %d, zero-padded %0Nd or\n"
         "Blender's #### (N '#': N digits), %% for a percent sign; without a frame\n"
         "number the stem of a single frame as given (--name duck: duck.exr). %q\n"
         "places the quilt's Looking Glass tag _qsCxRaA (fox%q.####: fox_qs8x6a0.75.0005\n"
         "for the quilt, fox.0005 for the other files); without it a still's quilt ends\n"
         "with the tag, and a sequence's has it before the frame number, which stays\n"
         "the last digit group, as Blender and other sequence readers expect",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           check_name_pattern(v);
           o.job.products.name = v;
         }},
        {"--compression", nullptr, "C",
         "EXR compression: none, zip, zip-fast (ZIP through ISA-L's igzip alone: a\n"
         "third of zip's writer CPU, 10% larger files; any reader opens it), piz, rle,\n"
         "dwaa, dwab (lossy DCT of R, G, B at OpenEXR's level 45, for review renders; A\n"
         "and Z stay exact; views and quilts only: refused for the encoded image)\n"
         "(default zip)",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.compression = v; }},
    }};

const RenderSection kSequenceOptions = {
    "sequences (an animated glTF plays; frame f samples time f / fps; before the animation's first key\n"
    "and after its last a frame holds the first or last pose, as glTF clamps):",
    {
        {"--frames", nullptr, "LIST",
         "frames to render: N, A:B (inclusive), A:B:STEP, a comma list of these\n"
         "(0:99,120,130:140), or all (default 0). all = the frames whose times lie\n"
         "inside the animation's keys, ceil(start x fps) to floor(end x fps); with\n"
         "--turntable one turn, 0 to FRAMES-1, however long the animation; frame 0\n"
         "for a still scene. Frames outside the keys get a warning, except all",
         set_frames},
        {"--frame", nullptr, "N", "", set_frames},  // not listed: --frames in the singular
        {"--fps", nullptr, "F", "frames per second (default 24)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.sequence.fps = parse_double(v, name);
           if (!(o.job.sequence.fps > 0.0) || o.job.sequence.fps > 10000.0)
             throw Error("invalid --fps: must be in (0, 10000]");
         }},
        {"--animation", nullptr, "A",
         "NAME, INDEX, all (every animation at once) or none (the rest pose);\n"
         "default: the first one",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           if (v.empty()) throw Error("invalid --animation '': expected a name, an index, all or none");
           o.job.sequence.animation = v;
         }},
        {"--turntable", nullptr, "DEG:FRAMES",
         "turn the scene DEG degrees every FRAMES frames about the vertical axis\n"
         "through its framing center (360:96 loops every 96 frames)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           const auto colon = v.find(':');
           if (colon == std::string::npos)
             throw Error("invalid --turntable '" + v + "': expected DEG:FRAMES, e.g. 360:96");
           o.job.sequence.turntable = true;
           o.job.sequence.turntable_deg = parse_double(v.substr(0, colon), name);
           o.job.sequence.turntable_frames = parse_int(v.substr(colon + 1), name, 1, 1 << 30);
         }},
        {"--resume", nullptr, nullptr, "skip frames whose files are all present; refuse a changed configuration",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.resume = true; }},
        {"--overwrite", nullptr, nullptr,
         "render even though the folder keeps frames of another configuration\n"
         "outside --frames (a warning counts them; without it the run refuses);\n"
         "with --resume: also re-render listed frames of another configuration",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.overwrite = true; }},
        {"--print-outputs", nullptr, nullptr,
         "print the files each frame of the job would be written to, one JSON\n"
         "line a frame ({\"frame\", \"sidecar\", \"outputs\": {kind: file}}), and\n"
         "exit without rendering or creating anything (for tools that drive pmr)",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.print_outputs = true; }},
        {"--quiet", "-q", nullptr, "print only errors and warnings",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.quiet = true; }},
        {"--shard", nullptr, "K/N|auto",
         "render only task K's share of the frames (interleaved: positions K, K+N,\n"
         "...); auto reads a Slurm, Kubernetes, AWS Batch, PBS, SGE or LSF array index\n"
         "(--shard-count N where the environment lacks the count, --shard-first F\n"
         "for PBS arrays not starting at 0); see docs/farm/README.md",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.shard = v; }},
        {"--shard-count", nullptr, "N", "",  // not listed: --shard's description explains it
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.shard_count = parse_int(v, name, 1, 1 << 30);
         }},
        {"--shard-first", nullptr, "F", "",  // not listed: --shard's description explains it
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.shard_first = parse_int(v, name, 0, 1 << 30);
         }},
    }};

const RenderSection kRigOptions = {
    "rig:",
    {
        {"--preset", nullptr, "NAME",
         "a display: paper-8k (default), lg-portrait, lg-go, lg-16, lg-32, ...\n"
         "(--preset help lists them); other options override its values",
         applied_first},
        {"--display-config", nullptr, "F",
         "a Looking Glass panel's own calibration file (visual.json): display,\n"
         "encoder and the model's recommended views (docs/DISPLAYS.md)",
         applied_first},
        {"--views", nullptr, "N", "number of views (default 96)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.rig.views = parse_int(v, name, 1, PMR_MAX_VIEWS);
         }},
        {"--view-size", nullptr, "WxH",
         "view raster in pixels (default 1024x512; each side <= " + std::to_string(PMR_MAX_RASTER) + ")",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           const auto d = parse_dims(v, name, 2, PMR_MAX_RASTER);
           o.job.rig.view_w = d[0], o.job.rig.view_h = d[1];
         }},
        {"--cone", nullptr, "DEG", "view cone (default 80)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.rig.cone_deg = parse_double(v, name);
           if (!(o.job.rig.cone_deg > 0.0 && o.job.rig.cone_deg < 180.0))
             throw Error("invalid --cone '" + v + "': expected degrees in (0, 180)");
         }},
        {"--yfov", nullptr, "DEG", "vertical field of view (default from the display: 2 atan(46.5 / 200))",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.rig.yfov_deg = parse_double(v, name);
           if (!(o.job.rig.yfov_deg > 0.0 &&
                 o.job.rig.yfov_deg < 180.0))  // 0 would silently mean "the display's default"
             throw Error("invalid --yfov '" + v + "': expected degrees in (0, 180)");
         }},
        {"--camera-spacing", nullptr, "S",
         "linear (PMR's, default for paper-8k) or angular (Looking Glass: D tan(cone\n"
         "((i + 1/2) / N - 1/2)), default for the Looking Glass presets; each\n"
         "angular camera moves onto a fine fixed-point grid (docs/DESIGN.md)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           if (v != "linear" && v != "angular")
             throw Error("invalid --camera-spacing '" + v + "': expected linear or angular");
           o.job.rig.angular_spacing = v == "angular";
         }},
        {"--camera", nullptr, "NAME|#K",
         "use the scene's glTF camera (pose and field of view) instead of framing the\n"
         "scene itself (--framing): NAME the name of the node that places it (as\n"
         "Blender names the camera object), else the camera's own name; #K its index;\n"
         "a name several match is an error (pmr info lists the cameras)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           if (v.empty()) throw Error("invalid " + name + ": expected a camera index or name");
           o.job.camera = v;
         }},
        {"--background", nullptr, "R,G,B[,A]|environment",
         "a linear colour behind the encoded image, views, quilt and previews (default\n"
         "transparent black; A defaults to 1). The encoded image is composited per\n"
         "subpixel; its PNG preview is always opaque (over black). With a Looking Glass\n"
         "preset or --display-config the quilt PNG is opaque black by default.\n"
         "environment: the pbr model's environment (--environment), alpha 1, drawn on\n"
         "a plane at --background-depth so that it stays sharp on the panel",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.background = parse_background(v); }},
        {"--background-depth", nullptr, "focal|inf|Z",
         "where --background environment is drawn: on the focal plane (default; the\n"
         "same picture in every view), at view-space depth Z from the center camera\n"
         "(scene units), or at infinity (inf); its disparity is clamped to 1 view\n"
         "pixel between neighbouring views, beyond which the panel doubles it",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           parse_backdrop_depth(v);  // checked here, applied once --background is known
           o.background_depth = v;
         }},
        {"--framing", nullptr, "box|sphere",
         "how the camera frames the scene: box (default), the largest picture that keeps\n"
         "the corners of the scene's box inside the first and last views; sphere (the\n"
         "default of --turntable), its bounding sphere fits the view's height and width,\n"
         "so the picture keeps its size as the scene turns. Not with --camera",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           if (v != "box" && v != "sphere") throw Error("invalid " + name + " '" + v + "': expected box or sphere");
           o.job.rig.framing = v == "box" ? Framing::Box : Framing::Sphere;
           o.framing_given = true;
         }},
        {"--zoom", nullptr, "F",
         "the scene appears F times larger than --framing fits it (default 1); the camera\n"
         "moves closer along the same axis (--orbit's), the zero-parallax plane stays\n"
         "through the box's center. F > 1 cuts the scene at the views' edges. Not with\n"
         "--camera",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.rig.zoom = parse_double(v, name);
           if (!(o.job.rig.zoom >= 0.001 && o.job.rig.zoom <= 1000.0))
             throw Error("invalid --zoom: expected a factor from 0.001 to 1000");
           o.zoom_given = true;
         }},
        {"--orbit", nullptr, "AZ,EL",
         "move the framing camera around the scene (degrees; default 0,0 looks down -Z):\n"
         "EL > 0 looks down on it (-90 < EL < 90), AZ > 0 turns counter-clockwise seen\n"
         "from above; the view stays level, the parallax horizontal. Not with --camera",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           const size_t comma = v.find(',');
           if (comma == std::string::npos) throw Error("invalid " + name + " '" + v + "': expected AZ,EL in degrees");
           o.job.rig.orbit_az_deg = parse_double(v.substr(0, comma), name);
           o.job.rig.orbit_el_deg = parse_double(v.substr(comma + 1), name);
           check_orbit(o.job.rig.orbit_az_deg, o.job.rig.orbit_el_deg);
           o.orbit_given = true;
         }},
    }};

const RenderSection kDisplayOptions = {
    "display:",
    {
        {"--display", nullptr, "WxH", "display image in pixels (default 7680x4320)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           const auto d = parse_dims(v, name, 2, kMaxDisplaySide);
           o.job.display.width = d[0], o.job.display.height = d[1];
         }},
        {"--display-size", nullptr, "WxH", "physical size in cm (default 166x93; sets the aspect A)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           const auto x = v.find('x');
           if (x == std::string::npos) throw Error("invalid --display-size '" + v + "': expected WxH in cm");
           o.job.display.size_w_cm = parse_double(v.substr(0, x), name);
           o.job.display.size_h_cm = parse_double(v.substr(x + 1), name);
         }},
        {"--viewing-distance", nullptr, "CM", "(default 200)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.display.viewing_distance_cm = parse_double(v, name);
         }},
        {"--lens-pitch", nullptr, "L", "lens pitch in subpixels (default 16)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.display.lens_pitch = parse_rational(v, name);
           if (o.job.display.lens_pitch.num <= 0) throw Error("invalid --lens-pitch '" + v + "': must be positive");
         }},
        {"--tan-slant", nullptr, "T", "tangent of the lens slant (default 1/18)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.display.tan_slant = parse_rational(v, name);
         }},
        {"--offset", nullptr, "O",
         "subpixel offset (default -L/(2N) = -1/12)\n"
         "(L, T, O accept decimals or fractions like 1/18; evaluated exactly)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.display.offset = parse_rational(v, name);
           o.offset_given = true;
         }},
        {"--reverse-views", nullptr, nullptr, "use view N-1-v instead of v",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.display.reversed = true; }},
        {"--bilinear", nullptr, nullptr, "sample views bilinearly (default nearest)",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.display.bilinear = true; }},
        {"--blend-views", nullptr, nullptr,
         "blend the two nearest views by the lens phase, as Looking Glass's\n"
         "webxr shader does by default (default: one view per subpixel)",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.display.blend_views = true; }},
    }};

const RenderSection kPipelineOptions = {
    "pipeline:",
    {
        {"--tile", nullptr, "XxYxV", "3D tile of the tile/fine raster, voxels over x, y, view (default 16x2x16)",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           const auto d = parse_dims(v, name, 3, kMaxTileSide);
           o.job.pipeline.tile_x = d[0], o.job.pipeline.tile_y = d[1], o.job.pipeline.tile_v = d[2];
         }},
        {"--method", nullptr, "M",
         "pmr (default), multipass (one conventional pass per view) or duplicate\n"
         "(every triangle copied per view into a 2D-tiled view atlas)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.pipeline.method = parse_method(v);
           o.method_given = true;
         }},
        {"--sampling", nullptr, "S",
         "view (default): the views rendered on their grids, each subpixel reading\n"
         "its view's nearest pixel; subpixel: every display subpixel rasterized at\n"
         "its own sample in its own view (docs/SAMPLING.md; the default of the\n"
         "presets listed there, which --bilinear, --blend-views or a --method\n"
         "other than pmr turn back to view sampling with a notice)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.pipeline.sampling = parse_sampling(v);
           o.sampling_given = true;
         }},
        {"--samples", nullptr, "S",
         "samples per pixel: 4 (default), 8 or 16 (Direct3D's multisample patterns),\n"
         "or 1 (the pixel center): coverage and depth per sample, each winner shaded\n"
         "once per pixel, the pixel the mean of its samples (alpha is coverage)",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.pipeline.samples = parse_samples(v); }},
        {"--texture-filter", nullptr, "F",
         "trilinear (default): every texture's mip chain, the level of detail from the\n"
         "analytic screen-space derivatives of the texture coordinates in the voxel's\n"
         "own view, and pbr's specular antialiasing; bilinear: level 0 alone, no\n"
         "specular antialiasing, as before mips (docs/SAMPLING.md)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.pipeline.texture_filter = parse_texture_filter(v);
         }},
    }};

const RenderSection kShadingOptions = {
    "shading (docs/SHADING.md):",
    {
        {"--variant", nullptr, "NAME|#K",
         "draw the scene's material variant NAME (or #K, its index; KHR_materials_variants,\n"
         "pmr info lists them) instead of its default materials",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           if (v.empty()) throw Error("invalid " + name + ": expected a variant's name or index");
           o.job.variant = v;
         }},
        {"--shading", nullptr, "S",
         "pbr (default): glTF metallic-roughness with every material map, seen from\n"
         "each view's own camera, so highlights move across the views; lit by the\n"
         "file's KHR_lights_punctual lights (moving with their nodes; without any,\n"
         "a default directional light only with --environment uniform) and the\n"
         "environment (the built-in studio by default);\n"
         "lambert: base colour x (0.2 + 0.8 max(0, n.l)), the same in every view,\n"
         "one fixed light (faster)",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.pipeline.shading = parse_shading(v); }},
        {"--shadows", nullptr, "on|off",
         "pbr: every light casts shadows, from maps rendered once per frame and\n"
         "shared by every view (default on); off: no shadows, the images of pmr\n"
         "before 0.26 bit for bit (docs/SHADING.md, \"Shadows\")",
         [](RenderOptions& o, const std::string& v, const std::string&) { o.job.pipeline.shadows = parse_shadows(v); }},
        {"--ground", nullptr, "shadow|none",
         "pbr with shadows on: shadow: a shadow catcher under the scene at the\n"
         "lowest point of the framing, showing only the shadows cast on it, as\n"
         "black of that opacity (like Blender's shadow catcher); none (default)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           if (v != "shadow" && v != "none") throw Error("unknown --ground '" + v + "' (expected shadow or none)");
           o.job.pipeline.ground_shadow = v == "shadow";
         }},
        {"--environment-occlusion", nullptr, "on|off",
         "pbr with shadows on: the environment's light is scaled by the fraction\n"
         "of it the scene lets through, from 64 directional maps (default on);\n"
         "off: the environment lights every point whole (faster: a sun under\n"
         "--environment uniform costs about 1.1x its unshadowed frame instead of\n"
         "about 5x; docs/SHADING.md, \"The environment's occlusion\")",
         [](RenderOptions& o, const std::string& v, const std::string& name) {
           o.job.pipeline.environment_occlusion = parse_on_off(v, name);
         }},
        {"--exposure", nullptr, "EV", "the colour times 2^EV, either model (default 0)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.pipeline.exposure_ev = parse_exposure(v);
         }},
        {"--environment", nullptr, "E",
         "pbr: what lights the scene besides its own lights (they stay):\n"
         "studio (default): a built-in studio room, grey walls and soft boxes\n"
         "above, left, right and behind the camera;\n"
         "uniform: radiance 0.2 from everywhere, with a default directional light\n"
         "when the file has no lights (pmr's look before 0.19);\n"
         "FILE: an equirectangular image of linear radiance (.hdr or .exr, path\n"
         "relative to the current folder; ./studio for a file of that name), -Z\n"
         "its middle column, +Y its top row; prefiltered once per run (1-2.5 s\n"
         "for 1024x512). Given explicitly, needs --shading pbr",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.environment = parse_environment(v);
           o.environment_given = true;
         }},
        {"--environment-rotation", nullptr, "DEG",
         "pbr: turn the studio or the image DEG degrees counter-clockwise seen\n"
         "from above\n"
         "(+X moves toward -Z; default 0)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.environment_rotation_deg = parse_environment_rotation(v);
           o.environment_rotation_given = true;
         }},
        {"--environment-intensity", nullptr, "X",
         "pbr: scales the environment, whichever it is (0 turns it off;\n"
         "default 1)",
         [](RenderOptions& o, const std::string& v, const std::string&) {
           o.job.pipeline.environment_intensity = parse_environment_intensity(v);
         }},
        {"--verbose", "-v", nullptr, "per-stage device times and queue sizes",
         [](RenderOptions& o, const std::string&, const std::string&) { o.job.verbose = true; }},
    }};

const RenderSection kInputOptions = {
    "untrusted input (docs/SECURITY.md):",
    {
        {"--allow-outside-scene-folder", nullptr, nullptr,
         "read files the scene names outside its folder (by default a\n"
         "buffer or image that resolves outside it is an error); recorded in the sidecar",
         [](RenderOptions& o, const std::string&, const std::string&) {
           o.job.input_limits.allow_outside_scene_folder = true;
         }},
        {"--limit", nullptr, "KEY=VALUE[,KEY=VALUE...]",
         "raise or lower a budget (VALUE an integer, K/M/G/T = x1024^n):",
         [](RenderOptions& o, const std::string& v, const std::string&) { parse_limits(v, o.job.input_limits); },
         limit_help},
    }};

// A bare argument is the scene.
void set_scene(RenderOptions& o, const std::string& arg) {
  if (!o.job.scene.empty()) throw Error("more than one scene given ('" + o.job.scene + "' and '" + arg + "')");
  o.job.scene = arg;
}

const OptionTable<RenderOptions> kRenderTable = {"render",
                                                 25,
                                                 {&kOutputOptions, &kSequenceOptions, &kRigOptions, &kDisplayOptions,
                                                  &kPipelineOptions, &kShadingOptions, &kInputOptions},
                                                 set_scene};

// The options after apply_display_source: anything they throw is a usage error (they read no file).
void parse_arguments(RenderOptions& o, const std::vector<std::string>& args) {
  parse_by_table(kRenderTable, o, args);
  // a still is one frame asked for by its number; anything else is (part of) a sequence, whose quilts
  // are named for sequence readers (frame_names.h)
  o.job.products.sequence =
      !o.job.shard.empty() || o.job.frames.empty() || o.job.frames.find_first_not_of("0123456789") != std::string::npos;
  if (o.zoom_given && !o.job.camera.empty())
    throw Error(
        "--zoom scales the framing of the scene's box or sphere; a glTF camera (--camera) sets its own: "
        "give one of them");
  if (o.framing_given && !o.job.camera.empty())
    throw Error(
        "--framing chooses how pmr's own camera frames the scene; a glTF camera (--camera) sets its own: "
        "give one of them");
  // the default frames the box; a turntable turns it, and its sphere keeps the picture the same size
  if (!o.framing_given) o.job.rig.framing = o.job.sequence.turntable ? Framing::Sphere : Framing::Box;
  if (o.orbit_given && !o.job.camera.empty())
    throw Error(
        "--orbit moves the camera that frames the scene; a glTF camera (--camera) sets its own: "
        "give one of them");
}

}  // namespace

RenderOptions parse_render_options(const std::vector<std::string>& args) {
  RenderOptions o;
  // the command line's defaults (docs/DESIGN.md section 3b): antialiased, as Blender and the glTF viewers
  // are; the library's PipelineConfig keeps the point-sampled images its tests compare bit for bit
  o.job.pipeline.samples = 4;
  o.job.pipeline.texture_filter = TextureFilter::Trilinear;
  o.job.pipeline.shadows = true;
  apply_display_source(o, args);  // a bad --display-config file is bad input (exit 1), not a usage error
  as_usage([&] { parse_arguments(o, args); });
  return o;
}

namespace {

// --background environment shows the pbr model's environment, on a plane at --background-depth.
void check_background(RenderOptions& o) {
  Background& bg = o.job.background;
  if (!o.background_depth.empty() && !bg.environment)
    throw UsageError("--background-depth places --background environment: add it");
  if (!o.background_depth.empty()) bg.depth = parse_backdrop_depth(o.background_depth);
  if (bg.environment && o.job.pipeline.shading != Shading::Pbr)
    throw UsageError("--background environment shows the pbr model's environment: add --shading pbr");
}

void finalize_options(RenderOptions& o) {
  // glass over a transparent background lets it through where it sees past the scene (DESIGN 4c)
  o.job.pipeline.clear_glass = o.job.background.transparent();
  check_background(o);
  if (o.job.display.blend_views && o.job.display.bilinear)
    throw UsageError("--blend-views and --bilinear cannot be combined");
  if (o.job.pipeline.ground_shadow && (o.job.pipeline.shading != Shading::Pbr || !o.job.pipeline.shadows))
    throw UsageError("--ground shadow needs --shading pbr and --shadows on: it shows the shadows cast on it");
  check_environment_options(o.job.environment, o.environment_given, o.environment_rotation_given,
                            o.job.pipeline.shading, o.job.warnings);
  if (o.job.pipeline.sampling == Sampling::Subpixel && !o.sampling_given) {
    // the preset's default: options that need the views rendered on their grids take precedence
    const std::string needs_views = o.job.pipeline.method != Method::Pmr
                                        ? "--method " + std::string(to_string(o.job.pipeline.method))
                                    : o.job.display.bilinear    ? "--bilinear"
                                    : o.job.display.blend_views ? "--blend-views"
                                    : previews_need_views(o)    ? "an OpenColorIO view transform (--ocio or $OCIO)"
                                                                : "";
    if (!needs_views.empty()) {
      o.job.pipeline.sampling = Sampling::View;
      o.job.warnings.push_back(needs_views +
                               " samples the rendered views: --sampling view instead of the "
                               "display's default, subpixel");
    } else if (!o.job.products.encoded) {
      o.job.pipeline.sampling = Sampling::View;  // no encoded image: nothing to sample by subpixel
    }
  }
  if (o.job.pipeline.sampling == Sampling::Subpixel) {
    check_subpixel_sampling(o.job.pipeline.method, o.job.display);  // pmr unless --method says otherwise
    if (previews_need_views(o))
      throw UsageError(
          "the panel PNG through an OpenColorIO view transform is encoded from the transformed views, "
          "which --sampling subpixel does not render: use --sampling view");
    if (!o.job.products.encoded) {  // the views are rendered on their grids in either case
      o.job.pipeline.sampling = Sampling::View;
      o.job.warnings.push_back(
          "--sampling subpixel samples the encoded image, which --write does not ask for: "
          "ignored");
    }
  }
  if (!o.offset_given) {
    o.job.display.offset = default_offset(o.job.display.lens_pitch, o.job.rig.views);
  }
}

}  // namespace

void finalize_render_options(RenderOptions& o) {
  as_usage([&] { finalize_options(o); });  // combinations of options
}

std::string main_help() {
  return "pmr - multi-view light-field renderer (parallel multi-view polygon rasterization on OpenCL)\n"
         "\n"
         "usage:\n"
         "  pmr render [SCENE.gltf|SCENE.glb] [options]   render N views and the encoded display image\n"
         "  pmr bench [SCENE] [options]                  performance sweeps over view count and method\n"
         "  pmr quality [SCENE] [options]                sampling error against a 4x finer reference\n"
         "  pmr info                                     list OpenCL platforms and devices\n"
         "  pmr info SCENE                               what a scene holds (cameras, animations, ...)\n"
         "  pmr verify DIR --frames LIST                 which frames of a sequence are missing or broken\n"
         "  pmr --version                                the program version (as sidecars record it)\n"
         "  pmr --help | pmr render --help\n"
         "\n"
         "exit status: 0 success; 1 bad input, runtime error or out of memory; 2 usage error (unknown option,\n"
         "bad option value); 3 internal error; 128 + N when stopped by signal N (130 for Ctrl-C)\n";
}

std::string render_help() {
  return "usage: pmr render [SCENE] [options]\n"
         "Renders SCENE (glTF 2.0, .gltf or .glb; default: the bundled data/default_scene.glb) as N views\n"
         "and interlaces them into the display's subpixel image. Defaults are the preset paper-8k:\n"
         "96 views of 1024x512, a 7680x4320 display of 166x93 cm seen from 200 cm, 80 degree view cone.\n"
         "\n" +
         options_help(kRenderTable) +
         "Environment: PMR_DEVICE=substring selects the OpenCL device by name (default: first CPU device).\n"
         "Docs in the source tree: README.md, docs/DESIGN.md (rig, framing, encoder, files), docs/SHADING.md.\n";
}

}  // namespace pmr
