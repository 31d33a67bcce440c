#pragma once
/// The picture options shared by the commands that write a run's outputs (run, replay, fuse).
#include <CLI/CLI.hpp>

#include "romo/pipeline/outputs.hpp"

namespace romo::tools {

/// --no-pictures and --picture-span M, written into @p out (which must outlive parsing).
void AddPictureOptions(CLI::App& cmd, pipeline::OutputOptions& out);

}  // namespace romo::tools
