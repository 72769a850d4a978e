// Draws a soak run's samples (tests/link/soak.py writes samples.csv): each
// daemon's resident memory and open file descriptors over the run, one line
// per daemon, so growth shows as a slope and a restart as a drop.
//   soak_plot SAMPLES.csv OUT.png
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "viz/canvas.hpp"
#include "viz/line_plot.hpp"

using namespace tomomap;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: soak_plot SAMPLES.csv OUT.png\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  std::string line;
  if (!std::getline(in, line) || line.rfind("minute,agent,pid,rss_mb,hwm_mb,fds", 0) != 0) {
    std::fprintf(stderr, "soak_plot: %s is not a soak.py samples.csv\n", argv[1]);
    return 2;
  }
  std::map<std::string, viz::LineSeries> rss, fds;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string minute, agent, pid, rss_mb, hwm_mb, fd_count;
    if (!std::getline(row, minute, ',') || !std::getline(row, agent, ',') || !std::getline(row, pid, ',') ||
        !std::getline(row, rss_mb, ',') || !std::getline(row, hwm_mb, ',') || !std::getline(row, fd_count, ','))
      continue;
    double at = 0, resident = 0, open = 0;
    try {
      at = std::stod(minute), resident = std::stod(rss_mb), open = std::stod(fd_count);
    } catch (const std::exception&) {
      std::fprintf(stderr, "soak_plot: skipped a row that is not numbers: %s\n", line.c_str());
      continue;
    }
    for (auto* s : {&rss[agent], &fds[agent]}) {
      s->name = agent;
      s->x.push_back(at);
    }
    rss[agent].y.push_back(resident);
    fds[agent].y.push_back(open);
  }
  viz::LinePanel memory{"resident memory of each daemon", "minutes", "RSS [MB]", {}};
  viz::LinePanel files{"open file descriptors of each daemon", "minutes", "file descriptors", {}};
  for (auto& [agent, s] : rss) memory.series.push_back(s);
  for (auto& [agent, s] : fds) files.series.push_back(s);
  viz::writePng(argv[2], viz::stack({viz::drawLinePanel(memory, viz::Axes::Linear),
                                     viz::drawLinePanel(files, viz::Axes::Linear)}));
  return 0;
}
