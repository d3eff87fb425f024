// What the benchmark programs share: the calling thread's and the process's CPU clocks,
// the command line of those that take `[--repeats N] [CONFIG.yaml]`, and a main that
// reports a bad argument or input file on one line instead of crashing.
#pragma once

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <string>

namespace mcrewave::bench {

// CPU time of the calling thread [s].
inline double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// User + system CPU time of the process, all threads [s].
inline double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// `[--repeats N] [CONFIG.yaml]`: *repeats (at least 1) and *path keep their values
// when not given.
inline void ParseRepeatsAndConfig(int argc, char** argv, int* repeats, std::string* path) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      *repeats = std::max(1, std::atoi(argv[++i]));
    } else {
      *path = argv[i];
    }
  }
}

// Runs a benchmark's own main; an exception (a config, CSV or manifest it cannot read,
// an argument it cannot use) is reported as `error: <what>` on stderr with exit code 2.
inline int GuardedMain(int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
  } catch (...) {
    std::fprintf(stderr, "error: an exception that is not a std::exception\n");
  }
  return 2;
}

}  // namespace mcrewave::bench
