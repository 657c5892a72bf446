#pragma once
// Input files (mobile files, OBJ meshes, WAV recordings, speed CSVs, contact-law records) are read whole, so
// only a regular file will do: a FIFO or a device such as /dev/zero has no end and was read until memory ran
// out, without the file named.

#include <string>

namespace aloft {

// Throws InputError "<path>: not a regular file" when `path` exists and is not a regular file (a directory,
// a FIFO, a device, a socket; a symbolic link counts as what it points to). A missing file passes: the
// caller's open names the error.
void require_regular_file(const std::string& path);

}  // namespace aloft
