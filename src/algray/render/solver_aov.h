// Per-pixel solver diagnostics of a render: the EXR channels `--aov` asks for and the work `--heatmap` draws.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "algray/io/image_io.h"
#include "algray/render/renderer.h"

namespace algray {

enum class SolverAov { Iterations, Isolation, Classification, Flags };

// Each solver channel: the word --aov takes and the EXR channel it adds. Adding one here (and filling it in
// add_solver_aovs) makes --aov, its help text and its errors offer it.
struct SolverAovName {
  SolverAov aov;
  const char* word;
  const char* channel;
};
inline constexpr std::array<SolverAovName, 4> kSolverAovs{{{SolverAov::Iterations, "iterations", "solver.refineIterations"},
                                                          {SolverAov::Isolation, "isolation", "solver.isolationSteps"},
                                                          {SolverAov::Classification, "classification", "solver.class"},
                                                          {SolverAov::Flags, "flags", "solver.flags"}}};
// "iterations, isolation, classification, flags", or with `last` "... classification or flags".
std::string aov_choices(const char* last = nullptr);

// "iterations,isolation,classification,flags" (any subset, any order) into the list; false with a message
// naming the accepted words on anything else.
bool parse_aov_list(const std::string& text, std::vector<SolverAov>& out, std::string& error);

// What the solver decided for a camera ray, from its hit record: higher is more suspicious, so a pixel shows
// the most telling of its antialiasing samples. EXR channel solver.class.
enum class SolverClass : std::uint32_t {
  OutsideExtent = 0,  // the ray missed the extent: nothing was solved
  NoRoot = 1,         // the isolation found no root on [t_in, t_out]
  Isolated = 2,       // a root isolated by a single sign change, then refined
  ExactZero = 3,      // P* came out exactly 0 at a subdivision point, or changed sign between two intervals
  Cluster = 4,        // an interval at the stopping width still held several roots; its sign change was taken
  HalvingLimit = 5,   // the isolation reached its depth limit before the stopping width
};
SolverClass solver_class(const HitRecord& hit);

// Per output pixel, summed (work) or combined (flags: or; class: max) over its antialiasing samples. The
// camera rays of the primary pass only: adaptive antialiasing's extra rays are not counted.
struct SolverWork {
  int width = 0, height = 0;
  std::vector<std::uint32_t> isolation_steps, refine_iterations, flags, classification;
  int samples = 1;                              // per side
  std::vector<std::uint32_t> total() const;     // isolation steps + refinement iterations
  std::vector<std::uint8_t> in_extent() const;  // 1 where some sample met the extent
};
// Zeros for a width x height image of `samples` x `samples` rays per pixel, for add_tile_work to fill.
SolverWork empty_solver_work(int width, int height, int samples);
// Adds one tile's camera rays, as the renderer hands them over (RenderOptions::on_primary_tile).
void add_tile_work(SolverWork& work, const PrimaryTile& tile);
// From a render's records (RenderOptions::keep_records, or the reference's hits).
SolverWork solver_work(const RenderResult& result);

// solver.refineIterations, solver.isolationSteps, solver.class and solver.flags, as asked: moved from `work`,
// which is left empty, so that a poster's channels are not held twice.
void add_solver_aovs(FrameImage& image, SolverWork&& work, const std::vector<SolverAov>& aovs);

}  // namespace algray
