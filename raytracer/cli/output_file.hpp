#pragma once
// Where `shtrace render` writes: a file named after the scene unless the
// user names one, and never over an existing file without saying so.
#include <functional>
#include <string>
#include <vector>

namespace shtrace {

// out/SCENE.png: a built-in scene's name, or a scene or model file's stem
// (`--scene models/bunny.obj` gives out/bunny.png).
std::string default_image_path(const std::string& scene);

// Writes a file through `write(path)`, which writes to a temporary and
// renames it (write_png, write_pfm), and returns the path written.
// `chosen` set: that path, replaced with a "replacing PATH" line if it exists.
// `chosen` empty: default_image_path(scene), or the first of SCENE-2.png,
// SCENE-3.png, ... that does not exist, claimed without ever replacing a file
// (even one another process writes meanwhile); a line names the one taken.
using FileWriter = std::function<void(const std::string& path)>;
std::string write_image(const std::string& chosen, const std::string& scene, const FileWriter& write);

// Prints "replacing PATH" if PATH exists: for files the user names.
void say_if_replacing(const std::string& path);

// Before any work: makes PATH's directory, and throws sh::Error where the
// directory cannot be written, where the name is too long for the temporary
// file beside it, or where PATH exists but is not a regular file (a
// directory, a device, a pipe: the rename that puts a file in place would
// replace a device's node).
void check_output_path(const std::string& path);
// Each output (empty ones left out by the caller) checked so, and none
// named twice or the same file as one of the command's inputs.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);
// No output the same file as one of `inputs` (those found once a scene is
// read: the models its file names).
void check_not_inputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

// Writing past the process's file-size limit (ulimit -f) then fails as a
// full disk does, with the temporary removed, where the signal it raises
// would end the process.
void ignore_file_size_limit();

// A name beside PATH for this process's temporary file.
std::string temp_name(const std::string& path);
// Moves a finished temporary file into place, or removes it and says why.
void move_into_place(const std::string& tmp, const std::string& path);
// Writes BYTES to PATH through a temporary file: no half file under PATH,
// and nothing left behind where the writing fails.  write_through_temp and
// write_image hold back SIGINT, SIGTERM, SIGHUP and SIGQUIT while they
// write: an interrupt ends the process once the file is in place.
void write_through_temp(const std::string& path, const std::string& bytes);

}  // namespace shtrace
