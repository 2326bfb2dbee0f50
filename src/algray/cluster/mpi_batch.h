// A batch across the ranks of an MPI job: rank 0 deals frames on request and writes the one log; every rank,
// rank 0 included, renders the frames it is dealt.
#pragma once

#include "algray/api/batch.h"
#include "algray/cluster/mpi_world.h"

namespace algray {

// Collective: every rank calls it with the same request. Frames go to whichever rank asks next, so a slow frame
// holds up only its own rank. Each log entry says which rank rendered it ("rank", "ranks"). Rank 0 alone
// reports through `callbacks` (progress, warnings, failures, with those of the other ranks), and every rank
// returns the batch's outcome, as one process would have it. Bad input found on any rank ends the batch on every
// rank before anything renders. A rank whose device fails logs that frame as failed and renders no more; the
// others go on, and only when every rank's device failed does the batch end as one process's would. A shard
// (--shard, a Slurm array task) or a jobs file on standard input is refused as bad input.
BatchOutcome run_mpi_batch(const BatchRequest& request, const BatchCallbacks& callbacks, MpiWorld& world);

}  // namespace algray
