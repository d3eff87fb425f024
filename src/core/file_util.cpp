#include "mcrewave/core/file_util.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

extern char** environ;

namespace mcrewave {
namespace {

// Runs gnuplot on `script` (which must draw to `temporary_png`); its output goes
// to `log_path`. Returns "" on success, else why it failed; sets
// *gnuplot_missing when gnuplot is not on the PATH.
std::string RunGnuplot(const std::string& script_path, const std::string& log_path,
                       bool* gnuplot_missing) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::string program = "gnuplot";
  std::vector<char*> arguments{program.data(), const_cast<char*>(script_path.c_str()), nullptr};
  pid_t pid = 0;
  const int spawn_error =
      posix_spawnp(&pid, "gnuplot", &actions, nullptr, arguments.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error != 0) {
    *gnuplot_missing = spawn_error == ENOENT;
    return std::string("cannot run gnuplot: ") + std::strerror(spawn_error);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return std::string("waiting for gnuplot: ") + std::strerror(errno);
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  std::ifstream log(log_path);
  std::string first_line;
  std::getline(log, first_line);
  return "gnuplot failed" + (first_line.empty() ? std::string() : ": " + first_line);
}

// Draws every (name, script_body) in one gnuplot process, each after `reset session`
// into a temporary PNG renamed to folder/name.png once the process succeeded; the
// script and log are named after `stem`. Returns "" on success, else why not (the
// figures renamed before a rename failed stay).
std::string DrawInOneProcess(const std::string& folder, const std::string& stem,
                             const std::vector<std::pair<std::string, std::string>>& figures,
                             bool* gnuplot_missing) {
  const std::string suffix = ".tmp." + std::to_string(::getpid());
  const std::string script_path = folder + "/" + stem + ".gp" + suffix;
  const std::string log_path = folder + "/" + stem + ".log" + suffix;
  std::vector<std::string> temporary_pngs;
  {
    std::ofstream script(script_path);
    for (const auto& [name, body] : figures) {
      temporary_pngs.push_back(folder + "/" + name + ".png" + suffix);
      script << "set output " << GnuplotString(temporary_pngs.back()) << "\n"
             << body << "\nset output\nreset session\n";
    }
    if (!script) {
      std::remove(script_path.c_str());
      return "cannot write " + script_path;
    }
  }
  std::string why = RunGnuplot(script_path, log_path, gnuplot_missing);
  std::remove(script_path.c_str());
  std::remove(log_path.c_str());
  for (std::size_t i = 0; i < figures.size() && why.empty(); ++i) {
    const std::string png = folder + "/" + figures[i].first + ".png";
    if (std::rename(temporary_pngs[i].c_str(), png.c_str()) != 0) {
      why = "cannot write " + png + ": " + std::strerror(errno);
    }
  }
  for (const std::string& temporary : temporary_pngs) std::remove(temporary.c_str());
  return why;
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& content) {
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  }
  const bool written = std::fwrite(content.data(), 1, content.size(), file) == content.size();
  const bool flushed = std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  const bool closed = std::fclose(file) == 0;
  if (!(written && flushed && closed) || std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot write " + path + ": " + reason);
  }
}

// A gnuplot single-quoted string ('' stands for one quote).
std::string GnuplotString(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

std::string GnuplotPngTerminal() {
  return "set terminal pngcairo size 1000,700 enhanced font 'sans,11'\nset datafile separator ','\n"
         "set key top right\nset grid\n";
}

std::string DrawGnuplotFigure(const std::string& folder, const std::string& name,
                              const std::string& script_body, bool* gnuplot_missing) {
  return DrawInOneProcess(folder, name, {{name, script_body}}, gnuplot_missing);
}

std::vector<std::string> DrawGnuplotFigures(
    const std::string& folder, const std::vector<std::pair<std::string, std::string>>& figures,
    bool* gnuplot_missing) {
  std::vector<std::string> why(figures.size());
  if (figures.empty()) return why;
  const std::string failure = DrawInOneProcess(folder, "figures", figures, gnuplot_missing);
  if (failure.empty()) return why;
  if (*gnuplot_missing) {
    for (std::string& reason : why) reason = failure;
    return why;
  }
  // One figure (or more) failed the shared process: each on its own, to keep the others.
  for (std::size_t i = 0; i < figures.size() && !*gnuplot_missing; ++i) {
    why[i] = DrawGnuplotFigure(folder, figures[i].first, figures[i].second, gnuplot_missing);
  }
  return why;
}

}  // namespace mcrewave
