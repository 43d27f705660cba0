#include "apps/dydp/gnuplot.hpp"

#include <cctype>
#include <cstdlib>
#include <filesystem>

#include "io/files.hpp"

namespace dydp::apps {

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

std::string file_safe(const std::string& name) {
  std::string s;
  for (char c : name) s += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return s;
}

bool run_gnuplot(const std::string& dir, const std::string& name, const std::string& script) {
  std::filesystem::create_directories(dir + "/plots");
  const std::string path = dir + "/plots/" + name + ".gp";
  io::write_file_atomically(path, script);
  return std::system(("gnuplot '" + path + "' 2>'" + dir + "/plots/" + name + ".log'").c_str()) == 0;
}

}  // namespace dydp::apps
