// Lists the backends registered in this program and fails unless every one
// the installed package was built with (SH_PACKAGE_BACKENDS, "a,b,c") is
// there: linking sh::sh is all it takes.
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <sh/sh.hpp>

int main() {
  std::vector<std::string> linked = sh::backend_names();
  std::istringstream wanted(SH_PACKAGE_BACKENDS);
  int missing = 0;
  for (std::string name; std::getline(wanted, name, ',');)
    if (std::find(linked.begin(), linked.end(), name) == linked.end()) {
      std::fprintf(stderr, "backend '%s' was built but is not registered\n", name.c_str());
      ++missing;
    }
  std::printf("backends linked:");
  for (const sh::BackendInfo& b : sh::backends()) std::printf(" %s (%zu variants)", b.name.c_str(), b.variants.size());
  std::printf("\n");
  return missing == 0 ? 0 : 1;
}
