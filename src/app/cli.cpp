#include "app/cli.hpp"

#include <cstdio>

#include "errors/errors.hpp"
#include "render/settings.hpp"
#include "scene/json_reader.hpp"

namespace wt::app {

void add_render_options(CLI::App& cmd, Job& job, std::string& encoding) {
  for (const Setting& s : settings()) {
    if (s.type == SettingType::Real) {
      // The one real setting, the noise threshold: above its lower bound, which
      // CLI::Range (inclusive) cannot say, so the job's check says it.
      cmd.add_option_function<double>(
          s.flag, [&job](double v) { job.noise_threshold = v; }, s.help);
      continue;
    }
    cmd.add_option_function<int64_t>(
           s.flag, [&job, id = s.id](int64_t v) { set_setting(job, id, v); }, s.help)
        ->check(CLI::Range(s.lo, s.hi));
  }
  add_define_option(cmd, job);
  cmd.add_option("--backend", job.backend, "cuda, cpu or auto (CUDA when a device is present)")
      ->check(CLI::IsMember(backend_choices()));
  cmd.add_option("--kernel", job.kernel, "the kernel: " + listed(kernel_names()))
      ->check(CLI::IsMember(kernel_names()));
  cmd.add_option("--devices", job.devices,
                 "split the render over these devices: all (default: every CUDA device) or indices such as 0,1 "
                 "(on the cpu backend, as many host devices, each a share of the threads)");
  cmd.add_option("--encoding", encoding, "PNG encoding: srgb or gamma2 (the reference renderer's curve)")
      ->check(CLI::IsMember(encoding_choices()));
  cmd.add_flag_callback("--no-nee", [&job] { set_setting(job, SettingId::Nee, 0); },
                        "no light sampling: pure path tracing (the same as --nee 0)");
  cmd.add_flag("--exr-float", job.exr_float, "OpenEXR output in 32-bit floats (default: half floats)");
  cmd.add_flag("--profile", job.profile, "print the load phases and the wavefront's per-stage times");
  cmd.add_flag("--denoise", job.denoise,
               "write the image Intel Open Image Denoise makes of the render (scripts/setup.sh installs it)");
  cmd.add_option("--denoise-quality", job.denoise_quality, "the denoiser's quality: high (default) or balanced")
      ->check(CLI::IsMember(denoise_quality_choices()));
  cmd.add_flag("--keep-noisy", job.keep_noisy, "with --denoise: write the render itself too, as NAME.noisy.EXT");
  cmd.add_option("--aov", job.aov,
                 "write these AOVs too, comma-separated: " + listed(aov_names()) +
                     " (layers of an .exr output, else NAME.<aov>.pfm beside it)");
}

void add_define_option(CLI::App& cmd, Job& job) {
  cmd.add_option_function<std::vector<std::string>>(
         "-D,--define", [&job](const std::vector<std::string>& defines) { add_defines(job, defines, "-D"); },
         "a Mitsuba scene's parameter: -D name=value (repeatable; before its <default>)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->allow_extra_args(false);
}

void set_encoding(Job& job, const std::string& encoding) {
  job.encoding = encoding == "gamma2" ? Encoding::Gamma2 : Encoding::Srgb;
}

Job RenderCommand::parsed() const {
  Job j = job;
  set_encoding(j, encoding);
  j.progress = !quiet;
  return j;
}

CLI::App* add_render_command(CLI::App& app, RenderCommand& cmd) {
  CLI::App* render = app.add_subcommand("render", "render one scene");
  render->add_option("scene", cmd.job.scene, "scene file: wavetrace's JSON, or a Mitsuba 3 scene (.xml)")->required();
  render->add_option("-o,--output", cmd.job.output,
                     "image file: .png (8-bit), .pfm (linear float) or .exr (linear half or float)")
      ->required();
  render->add_option("--stats", cmd.job.stats, "write render statistics as JSON");
  render->add_option("--checkpoint", cmd.job.checkpoint,
                     "write the film's sums here every --checkpoint-every seconds and on SIGINT/SIGTERM; "
                     "an existing checkpoint of the same render is resumed");
  render->add_option("--resume", cmd.job.resume, "continue the render a checkpoint holds");
  render->add_flag("-q,--quiet", cmd.quiet, "no progress line");
  add_render_options(*render, cmd.job, cmd.encoding);
  return render;
}

std::vector<std::string> render_arguments(const Job& job) {
  // "--name=value", so that a value starting with '-' is not taken for an option.
  std::vector<std::string> args = {"render", "--output=" + job.output};
  const auto add = [&](const char* flag, const std::string& value) {
    if (!value.empty()) args.push_back(std::string(flag) + "=" + value);
  };
  add("--stats", job.stats);
  add("--checkpoint", job.checkpoint);
  add("--resume", job.resume);
  for (const Setting& s : settings()) {
    if (const std::optional<int64_t> v = given_setting(job, s.id)) add(s.flag, std::to_string(*v));
  }
  for (const auto& [name, value] : job.defines) add("--define", name + "=" + value);
  add("--backend", job.backend);
  add("--kernel", job.kernel);
  if (job.devices != "all") add("--devices", job.devices);
  add("--encoding", encoding_choices()[job.encoding == Encoding::Srgb ? 0 : 1]);
  if (job.exr_float) args.push_back("--exr-float");
  if (job.denoise) {
    args.push_back("--denoise");
    add("--denoise-quality", job.denoise_quality);
  }
  if (job.keep_noisy) args.push_back("--keep-noisy");
  add("--aov", job.aov);
  if (job.noise_threshold) {
    char t[40];
    std::snprintf(t, sizeof t, "%.17g", *job.noise_threshold);
    add(setting(SettingId::NoiseThreshold).flag, t);
  }
  if (!job.progress) args.push_back("--quiet");
  if (job.profile) args.push_back("--profile");
  args.push_back("--");  // the scene, whatever its name
  args.push_back(job.scene);
  return args;
}

Job parse_render_arguments(const std::vector<std::string>& args) {
  CLI::App app;
  RenderCommand cmd;
  add_render_command(app, cmd);
  std::vector<const char*> argv = {"wavetrace"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  app.parse(static_cast<int>(argv.size()), argv.data());
  return cmd.parsed();
}

}  // namespace wt::app
