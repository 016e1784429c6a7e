#pragma once
// What a PLY file's header must say before the model library reads it.
#include <string>

namespace sh::rt {

// Throws sh::Error naming `path` and a line where a file the model
// library's PLY reader takes has a header that reader would not finish:
// one in which, reading it as the library does (ply_library_header.hpp),
// it finds no end_header, or an element the library reads with more
// instances than the file has bytes (or, in text, lines) after its header
// for them (it walks every instance, even of an element without
// properties, and reads a text file's last line again for every one the
// file lacks).  Any other file is left alone.
void check_ply_header(const std::string& path);

}  // namespace sh::rt
