# Run after lcm-gen (cmake -DHEADER_DIR=... -P HardenLcmDecode.cmake): bounds
# every count and string length that the generated C++ decoders trust.
#
# Debian's LCM 1.3.1 decodes an array by resizing it to the count read from
# the wire before it reads an element, and a string by assigning length - 1
# bytes. One message with a valid fingerprint and a negative count or length
# throws std::length_error out of the subscriber's callback (the process
# aborts), and a count of 2^26 allocates hundreds of MB before the decode
# fails. Every element takes at least one byte and every string at least its
# terminating NUL, so a count above the bytes left, or a length below one,
# cannot come from a real encoder: the decoder now returns -1 for it, as it
# does for any other short buffer.

cmake_minimum_required(VERSION 3.13)
if(NOT HEADER_DIR)
  message(FATAL_ERROR "HardenLcmDecode: HEADER_DIR not set")
endif()
file(GLOB headers ${HEADER_DIR}/*.hpp)
if(NOT headers)
  message(FATAL_ERROR "HardenLcmDecode: no headers in ${HEADER_DIR}")
endif()
set(marker "// ofn: counts and string lengths bounded (cmake/HardenLcmDecode.cmake)")
foreach(header ${headers})
  file(READ ${header} text)
  string(FIND "${text}" "${marker}" already)
  if(NOT already EQUAL -1)
    continue()
  endif()
  string(REGEX REPLACE
    "this->([A-Za-z0-9_]+)\\.resize\\(this->([A-Za-z0-9_]+)\\);"
    "if(this->\\2 < 0 || this->\\2 > maxlen - pos) return -1;\n    this->\\1.resize(this->\\2);"
    text "${text}")
  string(REGEX REPLACE
    "if\\(__([A-Za-z0-9_]+)_len__ > maxlen - pos\\) return -1;"
    "if(__\\1_len__ < 1 || __\\1_len__ > maxlen - pos) return -1;"
    text "${text}")
  # Every count-sized resize and every string read must now be guarded.
  # (Patterns without ';', which would split the lists.)
  string(REGEX MATCHALL "\\.resize\\(this->[A-Za-z0-9_]+\\)" resizes "${text}")
  string(REGEX MATCHALL "< 0 \\|\\| this->[A-Za-z0-9_]+ > maxlen - pos\\) return -1" guarded "${text}")
  list(LENGTH resizes resize_count)
  list(LENGTH guarded guarded_count)
  if(NOT resize_count EQUAL guarded_count)
    message(FATAL_ERROR "HardenLcmDecode: ${header}: ${guarded_count} of ${resize_count} array counts guarded")
  endif()
  string(REGEX MATCHALL "_len__ > maxlen - pos\\) return -1" strings "${text}")
  string(REGEX MATCHALL "_len__ < 1 \\|\\| __[A-Za-z0-9_]+_len__ > maxlen" bounded "${text}")
  list(LENGTH strings string_count)
  list(LENGTH bounded bounded_count)
  if(NOT string_count EQUAL bounded_count)
    message(FATAL_ERROR "HardenLcmDecode: ${header}: ${bounded_count} of ${string_count} string lengths guarded")
  endif()
  file(WRITE ${header} "${marker}\n${text}")
endforeach()
