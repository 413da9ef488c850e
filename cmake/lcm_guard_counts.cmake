# cmake -P lcm_guard_counts.cmake FILES="a.hpp;b.hpp": makes the decoders lcm-gen wrote refuse
# an array count that the message cannot hold, before they size anything from it.
#
# lcm-gen's C++ decoders (LCM 1.3.1, 1.4, 1.5) resize each variable-length array to the count
# just read from the wire and only then find out whether the bytes are there: a corrupt count
# of -1 throws std::length_error out of decode(), and one of 2^31 - 1 allocates (and zeroes)
# gigabytes first. Every array element takes at least one byte of the message, so a count
# below zero or above the bytes still unread is impossible: the decoder returns -1 for it, as
# for any other malformed message. A string's length counts its terminating NUL, so one below
# 1 is malformed too (the decoders checked only the upper bound, and assign(p, -1) threw
# std::length_error). Both found by fuzzing (fuzz/README.md).
foreach(file IN LISTS FILES)
  file(READ ${file} text)
  string(REGEX REPLACE
    "\n([ \t]*)(this->[A-Za-z0-9_]+(\\[[a-z0-9]+\\])*)\\.resize\\(this->([A-Za-z0-9_]+)\\);"
    "\n\\1if (this->\\4 < 0 || this->\\4 > maxlen - pos) return -1;  // kestrel: cmake/lcm_guard_counts.cmake\n\\1\\2.resize(this->\\4);"
    guarded "${text}")
  string(REGEX REPLACE
    "if\\((__[A-Za-z0-9_]+) > maxlen - pos\\) return -1;"
    "if(\\1 < 1 || \\1 > maxlen - pos) return -1;  // kestrel: cmake/lcm_guard_counts.cmake"
    guarded "${guarded}")
  if(NOT guarded STREQUAL text)
    file(WRITE ${file} "${guarded}")
  endif()
endforeach()
