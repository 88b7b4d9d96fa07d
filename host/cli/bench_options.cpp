#include "cli/bench_options.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "cli/option_table.h"
#include "cli/options.h"
#include "pmr/printable.h"
#include "pmr/error.h"

namespace pmr {

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string w;
  while (std::getline(ss, w, ',')) out.push_back(w);
  return out;
}

// The options pmr render reads for bench (rig, display, sequence): passed on to its parser after the
// others (parse_bench_options).
void pass_to_render(BenchOptions& o, const std::string& value, const std::string& name) {
  o.render_args.push_back(name);
  o.render_args.push_back(value);
}

void pass_flag_to_render(BenchOptions& o, const std::string&, const std::string& name) {
  o.render_args.push_back(name);
}

// --synthetic and --objects: the generator the option names, one scene per triangle count.
void set_generator(BenchOptions& o, const std::string& v, const std::string& name) {
  if (!o.generator.empty()) throw Error("give one of --synthetic and --objects, once");
  o.generator = name.substr(2);
  for (const auto& count : split(v)) {
    char* end = nullptr;
    const double n = std::strtod(count.c_str(), &end);
    if (count.empty() || *end != '\0' || !(n >= 1 && n <= 5e7))
      throw Error("invalid " + name + " '" + count + "': expected triangle counts (1 to 5e7), comma-separated");
    o.triangle_counts.push_back(size_t(n));
  }
  if (o.triangle_counts.empty()) throw Error("invalid " + name + ": expected triangle counts");
}

using BenchSection = OptionSection<BenchOptions>;

const BenchSection kSweepOptions = {
    nullptr,
    {
        {"--help", "-h", nullptr, "",  // not listed: the help itself
         [](BenchOptions& o, const std::string&, const std::string&) { o.help = true; }},
        {"--views", nullptr, "LIST", "view counts (default 1,2,4,8,16,32,48,64,96)",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.views_given = true;
           o.views.clear();
           for (const auto& n : split(v)) o.views.push_back(parse_render_options({"--views", n}).job.rig.views);
         }},
        {"--method", nullptr, "LIST", "pmr, multipass, duplicate (default all three)",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.methods.clear();
           for (const auto& m : split(v)) o.methods.push_back(parse_method(m));
         }},
    }};

// Not listed one by one: the heading names them.
const BenchSection kShadingOptions = {
    "  --shading S, --exposure EV, --environment E, --environment-rotation DEG,\n"
    "  --environment-intensity X, --shadows on|off, --environment-occlusion on|off   as for\n"
    "  pmr render (default pbr, studio, shadows and the environment's occlusion on)",
    {
        {"--shadows", nullptr, "on|off", "",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.shadows = parse_shadows(v); }},
        {"--environment-occlusion", nullptr, "on|off", "",
         [](BenchOptions& o, const std::string& v, const std::string& name) {
           o.environment_occlusion = parse_on_off(v, name);
         }},
        {"--shading", nullptr, "S", "",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.shading = parse_shading(v); }},
        {"--exposure", nullptr, "EV", "",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.exposure_ev = parse_exposure(v); }},
        {"--environment", nullptr, "E", "",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.environment_source = parse_environment(v);
           o.environment_given = true;
         }},
        {"--environment-rotation", nullptr, "DEG", "",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.environment_rotation_deg = parse_environment_rotation(v);
           o.environment_rotation_given = true;
         }},
        {"--environment-intensity", nullptr, "X", "",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.environment_intensity = parse_environment_intensity(v);
         }},
    }};

const BenchSection kMeasureOptions = {
    nullptr,
    {
        {"--sampling", nullptr, "LIST",
         "view, subpixel (subpixel with pmr only; default view, or a --preset's\n"
         "default): samples per frame are the voxels, or each display subpixel once",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.samplings.clear();
           o.samplings_given = true;
           for (const auto& m : split(v)) o.samplings.push_back(parse_sampling(m));
         }},
        {"--samples", nullptr, "LIST", "samples per pixel, each as for pmr render (default 4)",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.samples = parse_samples_list(v); }},
        {"--texture-filter", nullptr, "F", "trilinear (default) or bilinear, as for pmr render",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.texture_filter = parse_texture_filter(v); }},
        {"--frames", nullptr, "K", "timed frames per point after one warm-up frame (default 5)",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.frames = std::atoi(v.c_str());
           if (o.frames < 1 || o.frames > 1000) throw Error("invalid --frames '" + v + "': expected 1..1000");
         }},
        {"--csv", nullptr, "FILE", "write one row per point",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.csv = v; }},
        {"--keep", nullptr, "view|total",
         "view: every view is --view-size (default 1024x512); total: the total voxel\n"
         "count of 96 views of --view-size is held fixed (the paper's Fig. 15; views\n"
         "are capped at 4096x2048)",
         [](BenchOptions& o, const std::string& v, const std::string&) {
           o.keep = v;
           if (o.keep != "view" && o.keep != "total")
             throw Error("invalid --keep '" + o.keep + "': expected view or total");
         }},
        {"--synthetic", nullptr, "LIST",
         "procedural scenes of about these triangle counts instead of SCENE (a sweep:\n"
         "1000,10000,100000): UV spheres of ~200 triangles in a 4 x 2 x 3 box",
         set_generator},
        {"--objects", nullptr, "LIST",
         "the same with a CAD-like scene: 100 closed double-sided tori and rounded\n"
         "boxes at different depths, tiny triangles at 1M (1e6 is accepted)",
         set_generator},
        {"--save-scene", nullptr, "FILE",
         "write the one generated scene to FILE (.glb) and exit: `pmr bench FILE` on\n"
         "any build then renders the very same triangles",
         [](BenchOptions& o, const std::string& v, const std::string&) { o.save_scene = v; }},
        {"--no-check", nullptr, nullptr, "skip comparing the methods' images",
         [](BenchOptions& o, const std::string&, const std::string&) { o.check = false; }},
        {"--queue-stats", nullptr, nullptr,
         "after each point, histograms of its last frame's work (tile-queue entries\n"
         "per MTA and per tile, views and bounding-box pixels per MTA) and the stage\n"
         "times per unit of it",
         [](BenchOptions& o, const std::string&, const std::string&) { o.queue_stats = true; }},
    }};

// Not listed one by one: the heading names them.
const BenchSection kInputOptions = {
    "  --limit KEY=VALUE[,...], --allow-outside-scene-folder  budgets and confinement for SCENE's\n"
    "                      files, as for pmr render (docs/SECURITY.md)",
    {
        {"--limit", nullptr, "KEY=VALUE[,...]", "",
         [](BenchOptions& o, const std::string& v, const std::string&) { parse_limits(v, o.limits); }},
        {"--allow-outside-scene-folder", nullptr, nullptr, "",
         [](BenchOptions& o, const std::string&, const std::string&) { o.limits.allow_outside_scene_folder = true; }},
    }};

// Not listed one by one: the heading names them.
const BenchSection kRenderOptions = {
    "  --preset, --camera-spacing, --orbit, --view-size, --display, --tile and the display options are as for\n"
    "  pmr render (a preset as a user gets it: its view count, camera spacing and default sampling\n"
    "  unless --views, --camera-spacing, --sampling), and so are\n"
    "  --animation, --fps and --turntable: the timed frames are then frames 0..K-1 of that sequence.",
    {
        {"--preset", nullptr, "NAME", "", pass_to_render},
        {"--camera-spacing", nullptr, "S", "", pass_to_render},
        {"--view-size", nullptr, "WxH", "", pass_to_render},
        {"--display", nullptr, "WxH", "", pass_to_render},
        {"--tile", nullptr, "XxYxV", "", pass_to_render},
        {"--display-size", nullptr, "WxH", "", pass_to_render},
        {"--lens-pitch", nullptr, "L", "", pass_to_render},
        {"--tan-slant", nullptr, "T", "", pass_to_render},
        {"--offset", nullptr, "O", "", pass_to_render},
        {"--bilinear", nullptr, nullptr, "", pass_flag_to_render},
        {"--reverse-views", nullptr, nullptr, "", pass_flag_to_render},
        {"--cone", nullptr, "DEG", "", pass_to_render},
        {"--yfov", nullptr, "DEG", "", pass_to_render},
        {"--orbit", nullptr, "AZ,EL", "", pass_to_render},
        {"--animation", nullptr, "A", "", pass_to_render},
        {"--fps", nullptr, "F", "", pass_to_render},
        {"--turntable", nullptr, "DEG:FRAMES", "", pass_to_render},
    }};

// A bare argument is the scene.
void set_scene(BenchOptions& o, const std::string& arg) {
  if (!o.scene.empty()) throw Error("more than one scene given");
  o.scene = arg;
}

const OptionTable<BenchOptions> kBenchTable = {
    "bench", 22, {&kSweepOptions, &kShadingOptions, &kMeasureOptions, &kInputOptions, &kRenderOptions}, set_scene};

}  // namespace

BenchOptions parse_bench_options(const std::vector<std::string>& args) {
  BenchOptions o;
  parse_by_table(kBenchTable, o, args);
  RenderOptions r = parse_render_options(o.render_args);
  o.view_w = r.job.rig.view_w, o.view_h = r.job.rig.view_h;
  o.rig = r.job.rig;  // a Looking Glass preset's angular camera spacing included
  if (!o.views_given && std::find(o.render_args.begin(), o.render_args.end(), "--preset") != o.render_args.end())
    o.views = {r.job.rig.views};
  if (!o.samplings_given) o.samplings = {r.job.pipeline.sampling};  // the preset's default
  o.display = r.job.display;
  o.offset_given = r.offset_given;
  o.tile[0] = r.job.pipeline.tile_x, o.tile[1] = r.job.pipeline.tile_y, o.tile[2] = r.job.pipeline.tile_v;
  o.sequence = r.job.sequence;
  if (o.methods.empty() || o.views.empty() || o.samplings.empty()) throw Error("nothing to measure");
  std::vector<std::string> warnings;
  check_environment_options(o.environment_source, o.environment_given, o.environment_rotation_given, o.shading,
                            warnings);
  for (const std::string& w : warnings) std::fprintf(stderr, "pmr: warning: %s\n", terminal_text(w).c_str());
  const bool subpixel = std::find(o.samplings.begin(), o.samplings.end(), Sampling::Subpixel) != o.samplings.end();
  // subpixel rows are measured for pmr alone (the other methods' rows are skipped)
  if (subpixel) {
    const bool pmr = std::find(o.methods.begin(), o.methods.end(), Method::Pmr) != o.methods.end();
    check_subpixel_sampling(pmr ? Method::Pmr : o.methods[0], o.display);
  }
  if (!o.generator.empty() && !o.scene.empty())
    throw Error("give a SCENE or a generator (--synthetic, --objects), not both");
  if (!o.save_scene.empty() && o.triangle_counts.size() != 1)
    throw Error("--save-scene needs exactly one generated scene (--synthetic TRIS or --objects TRIS)");
  return o;
}

std::string bench_help() {
  return "usage: pmr bench [SCENE] [options]\n"
         "Times whole frames (render + encode, no file I/O) per view count and method.\n" +
         options_help(kBenchTable) +
         "Per point it prints the frame time, the per-stage device times, and the floor: the bytes a frame\n"
         "must move (each voxel written once, the display image written once) at the measured copy bandwidth.\n";
}

}  // namespace pmr
