#pragma once
// What a PLY file's header must say before the model library reads it.
#include <string>

namespace sh::rt {

// Throws sh::Error naming `path` and the line where a file that the model
// library's PLY reader takes (its first line begins with "ply", in any
// case) has a header that reader might not end reading: no end_header line
// as the reader reads lines, a line the format's plain grammar does not
// have (the reader ignores it, and its leftovers can lead it astray), or
// an element with more instances than the file has bytes after its header
// (the reader walks every instance, even of an element without
// properties).  Any other file is left alone.
void check_ply_header(const std::string& path);

}  // namespace sh::rt
