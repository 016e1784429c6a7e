#pragma once
// What a PLY file's header must say before the model library reads it.
#include <string>

namespace sh::rt {

// Throws sh::Error naming `path` and the line where a file that begins as
// the model library's PLY reader takes it ("ply", in any case) has a
// header that reader would not end reading: no end_header line, or an
// element with more instances than the file has bytes after its header
// (the reader walks every instance, even of an element without
// properties, and a count of 2^32 - 1 kept it busy past the load's time
// limit).  Any other file is left alone.
void check_ply_header(const std::string& path);

}  // namespace sh::rt
