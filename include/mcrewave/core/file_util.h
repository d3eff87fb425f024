// Writing result files atomically (a reader never sees a half-written file) and
// drawing figures with gnuplot.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace mcrewave {

// Writes content to a temporary file next to path, flushes it, then renames it
// onto path (atomic on POSIX file systems). On failure removes the temporary file,
// leaves any earlier file at path intact and throws std::runtime_error naming path.
void WriteFileAtomically(const std::string& path, const std::string& content);

// A gnuplot single-quoted string ('' stands for one quote).
std::string GnuplotString(const std::string& text);

// The first lines of a figure script: pngcairo 1000 x 700, CSV input (comma
// separator), key top right, grid.
std::string GnuplotPngTerminal();

// Draws folder/name.png with gnuplot from `script_body` (which must not set the
// output): the script, gnuplot's log and the PNG go to temporary names in
// `folder`, and the PNG is renamed into place only when gnuplot succeeded, so a
// reader never sees a half-drawn figure. Returns "" on success, else why not;
// sets *gnuplot_missing when gnuplot is not on the PATH.
std::string DrawGnuplotFigure(const std::string& folder, const std::string& name,
                              const std::string& script_body, bool* gnuplot_missing);

// DrawGnuplotFigure for every (name, script_body), in one gnuplot process (its start-up
// is most of a small figure's cost), each figure after `reset session`. Returns why each
// figure was not drawn ("" when it was): when the one process fails, every figure is
// drawn again on its own, so that only the failing ones are missing.
std::vector<std::string> DrawGnuplotFigures(
    const std::string& folder, const std::vector<std::pair<std::string, std::string>>& figures,
    bool* gnuplot_missing);

}  // namespace mcrewave
