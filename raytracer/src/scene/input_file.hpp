#pragma once
// Files a scene is read from: a scene file, a model file.
#include <string>

namespace sh::rt {

// Throws sh::Error naming `path` as `what` ("the scene file") unless it is
// a regular file this process can open: a FIFO would block the open, and a
// device would read without end, before any limit on the read applies.
void check_input_file(const std::string& path, const std::string& what);

}  // namespace sh::rt
