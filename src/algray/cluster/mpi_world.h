// The MPI job a process belongs to: MPI initialised while a MpiWorld lives, and this process's rank in it.
#pragma once

#include <mpi.h>

#include <chrono>

namespace algray {

class MpiWorld {
 public:
  // MPI_Init_thread with MPI_THREAD_FUNNELED: MPI calls come from the main thread only, while other threads
  // render. Throws std::runtime_error when the library cannot give that.
  MpiWorld();
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

// How long a waiting rank sleeps between two looks at MPI. Each look wakes a thread on a core that a renderer
// uses (Open MPI binds a rank to one core), so not too often; a frame or a band takes far longer than this.
inline constexpr std::chrono::milliseconds kMpiPollInterval{2};

// Waits for a request to complete, sleeping kMpiPollInterval between tests. Open MPI's blocking calls spin on a core while they
// wait; a rank waiting for a message sleeps instead, so that its core stays with the renderers beside it.
void wait_sleeping(MPI_Request& request);

// Collective: whether every rank says `ok`, without spinning.
bool every_rank_agrees(bool ok);

}  // namespace algray
