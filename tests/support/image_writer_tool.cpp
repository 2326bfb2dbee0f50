// Helper for test_image_io: writes a noisy image in a fresh process, optionally under a file-size limit or cleanup
// handlers.
//
// usage: image_writer_tool [--cleanup-handlers] [--fsize-limit=BYTES] SIDE SEED PATH...
//
// Builds a SIDE x SIDE image whose rgba and depth are uniform noise from std::mt19937(SEED) (the same
// recipe as noisy_image() in noisy_image.h, which test_image_io uses to check a finished file), then writes
// it to each PATH with write_exr or write_png, chosen by extension. Exit status: the number of writes
// that threw WriteError plus 10 for each that threw OutputError; 100 for bad usage, 101 for any other exception.
//
// The tests fork() and exec this instead of writing in a forked child, because the test process may
// already run OpenEXR's global thread pool, whose threads do not exist in a forked child.
#include <signal.h>
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <string>

#include "algray/io/image_io.h"
#include "noisy_image.h"

int main(int argc, char** argv) {
  bool cleanup_handlers = false;
  long long fsize_limit = -1;
  int arg = 1;
  for (; arg < argc && std::string(argv[arg]).rfind("--", 0) == 0; ++arg) {
    const std::string opt = argv[arg];
    if (opt == "--cleanup-handlers")
      cleanup_handlers = true;
    else if (opt.rfind("--fsize-limit=", 0) == 0)
      fsize_limit = std::atoll(opt.c_str() + 14);
    else
      break;
  }
  if (argc - arg < 3) {
    std::fprintf(stderr, "usage: %s [--cleanup-handlers] [--fsize-limit=BYTES] SIDE SEED PATH...\n", argv[0]);
    return 100;
  }
  const int side = std::atoi(argv[arg]);
  const auto seed = static_cast<std::mt19937::result_type>(std::atoll(argv[arg + 1]));
  if (side <= 0) {
    std::fprintf(stderr, "%s: SIDE must be positive\n", argv[0]);
    return 100;
  }

  const algray::FrameImage im = algray::testing::noisy_image(side, seed);

  if (cleanup_handlers) algray::install_output_cleanup_handlers();
  if (fsize_limit >= 0) {
    // Writes past the limit then fail with EFBIG instead of killing the process.
    ::signal(SIGXFSZ, SIG_IGN);
    struct rlimit limit {};
    limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(fsize_limit);
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) {
      std::perror("setrlimit");
      return 100;
    }
  }

  int failures = 0;
  try {
    for (int i = arg + 2; i < argc; ++i) {
      try {
        if (algray::format_from_extension(argv[i]) == algray::ImageFormat::Exr)
          algray::write_exr(argv[i], im);
        else
          algray::write_png(argv[i], im);
      } catch (const algray::WriteError&) {
        ++failures;  // expected under --fsize-limit; the test checks the count, so stay quiet
      } catch (const algray::OutputError&) {
        failures += 10;
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 101;
  }
  return failures;
}
