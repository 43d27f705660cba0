#include "apps/dydp/progress_bar.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>

namespace dydp::apps {

std::string format_duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[32];
  if (s >= 3600) std::snprintf(text, sizeof text, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
  else if (s >= 60) std::snprintf(text, sizeof text, "%ldm%02lds", s / 60, s % 60);
  else std::snprintf(text, sizeof text, "%lds", s);
  return text;
}

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), tty_(isatty(fileno(stderr))), start_(std::chrono::steady_clock::now()) {}

void ProgressBar::update(int done, int total) {
  if (total <= 0) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double left = done > 0 ? elapsed / done * (total - done) : 0.0;
  const int width = 30, filled = width * done / total;
  const std::string bar = "[" + std::string(filled, '#') + std::string(width - filled, '.') + "]";
  const std::string text = label_ + " " + bar + " " + std::to_string(done) + "/" + std::to_string(total) +
                           " runs, " + format_duration(elapsed) + " so far, " +
                           (done < total ? format_duration(left) + " left" : "done");
  if (tty_) {
    std::cerr << "\r" << text << "   " << std::flush;
    return;
  }
  const int tenth = 10 * done / total;
  if (tenth == last_tenth_) return;
  last_tenth_ = tenth;
  std::cerr << text << "\n";
}

void ProgressBar::finish() {
  if (tty_) std::cerr << "\r" << std::string(100, ' ') << "\r" << std::flush;
}

}  // namespace dydp::apps
