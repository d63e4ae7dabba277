# Writes OUTPUT, a C++ source defining `extern const char* const NAME` as the text of INPUT (a
# raw string literal), so report.html's script and stylesheet live in their own files.
# Usage: cmake -DINPUT=... -DOUTPUT=... -DNAME=... -P embed_text.cmake
file(READ "${INPUT}" text)
string(FIND "${text}" ")vv_embed\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw string's delimiter )vv_embed\"")
endif()
file(WRITE "${OUTPUT}.tmp" "// Generated from ${INPUT} by cmake/embed_text.cmake; do not edit.\n"
  "namespace vessel::reports {\nextern const char* const ${NAME};\n"
  "const char* const ${NAME} = R\"vv_embed(${text})vv_embed\";\n}  // namespace vessel::reports\n")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
