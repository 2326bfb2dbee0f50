// One image across the ranks of an MPI job: bands of rows dealt by rank 0, rendered by every rank, gathered into
// rank 0's film.
#pragma once

#include "algray/cluster/mpi_world.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"

namespace algray {

// The rows of the next band dealt, with `rows_left` of the image's still to deal: a share of what is left, so
// that bands shrink towards the end (guided scheduling) and the ranks finish together, but never below 1/64 of
// the image's height a rank, and never above 8 M pixels (a 256 MB film on the rank that renders it).
int band_rows(int rows_left, int image_height, int image_width, int ranks);

// Rank 0: deals the bands on request (its progress counts rows), renders its own on a thread of its own (RenderOptions::rows), and puts
// every rank's band into its film as it arrives, straight from the message. The film has depth and normal
// channels when `depth_and_normal` (outputs_hold_depth), and the other ranks send them then. Returns what
// renderer.render() would for the whole image, bit for bit the same film; the passes, rays and primary counts are the
// ranks' together, and `devices` lists every rank's devices. A band that fails on any rank fails the render (thrown as
// std::runtime_error naming the rank) once every rank has stopped.
RenderResult render_bands_as_rank0(Renderer& renderer, const Scene& scene, const RenderOptions& options,
                                   bool depth_and_normal, MpiWorld& world);

// Every other rank: asks rank 0 for bands, renders each into a film of its own rows, and sends back the channels
// rank 0's film has; holds one band at a time. Returns when rank 0 has no more. A band that fails is reported to
// rank 0, which fails the render; so is a rank without a renderer (null: its device did not open), with the
// reason `cannot_render`.
void render_bands_as_worker(Renderer* renderer, const Scene& scene, const std::string& cannot_render = "");

// Rank 0, when its render failed before it dealt a band (its own device did not open): answers every other
// rank that there is nothing to render, so that none waits for ever.
void release_workers(MpiWorld& world);

// After the render: rank 0 tells every rank the command's exit code, and each returns it.
int share_exit_code(int code, MpiWorld& world);

}  // namespace algray
