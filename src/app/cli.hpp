// The `render` command's options, shared by main and by `batch`, which runs each
// job as a `render` of its own process (render_arguments): one definition of the
// options, so that a job means the same on either path.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "app/job.hpp"

namespace wt::app {

// The options that render and batch share; they fill `job`, the encoding's name into
// `encoding` (apply it with set_encoding). Names, ranges and help of the numeric
// settings come from the settings table.
void add_render_options(CLI::App& cmd, Job& job, std::string& encoding);
// `-D name=value` (repeatable), a Mitsuba scene's parameters, into job.defines.
void add_define_option(CLI::App& cmd, Job& job);
void set_encoding(Job& job, const std::string& encoding);

// The `render` subcommand: what it parses lands in `job`, `encoding` and `quiet`;
// finish_render_job applies the last two to the job after parsing.
struct RenderCommand {
  Job job;
  std::string encoding = "srgb";
  bool quiet = false;
  Job parsed() const;
};
CLI::App* add_render_command(CLI::App& app, RenderCommand& cmd);

// The command line after the program name that renders `job`: "render", then an
// option for every field of the job that differs from a default Job, the scene last.
// Parsing it with add_render_command gives `job` back.
std::vector<std::string> render_arguments(const Job& job);
// The job such a command line renders (parsed as main parses it); throws
// CLI::ParseError for one that is not.
Job parse_render_arguments(const std::vector<std::string>& args);

}  // namespace wt::app
