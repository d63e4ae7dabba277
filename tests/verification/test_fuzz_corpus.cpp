// Replays the fuzz corpus (tests/fuzz/corpus, including inputs that once crashed the readers)
// through the .msh, STL and scene readers: each must return or throw InputError, nothing else.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/msh_io.hpp"
#include "meshes/stl_io.hpp"
#include "verification/scene.hpp"

using namespace vessel;

namespace {

template <class F>
int replay(const std::string& folder, F&& parse) {
  int count = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(VESSEL_FUZZ_CORPUS) / folder)) {
    SCOPED_TRACE(entry.path().string());
    const std::string data = test::read_text(entry.path());
    try {
      parse(data);
    } catch (const InputError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << "threw something other than InputError: " << e.what();
    }
    ++count;
  }
  return count;
}

}  // namespace

TEST(FuzzCorpus, MshReaderReturnsOrThrowsInputError) {
  EXPECT_GE(replay("msh",
                   [](const std::string& d) {
                     std::istringstream in(d);
                     (void)parse_msh(in, "corpus.msh");
                   }),
            4);
}

TEST(FuzzCorpus, StlReaderReturnsOrThrowsInputError) {
  EXPECT_GE(replay("stl", [](const std::string& d) { (void)parse_stl(d, "corpus.stl"); }), 2);
}

TEST(FuzzCorpus, SceneReaderReturnsOrThrowsInputError) {
  EXPECT_GE(replay("scene", [](const std::string& d) { (void)parse_scene(d, "corpus.toml"); }), 5);
}

TEST(FuzzCorpus, OnceCrashingMshInputsNowGiveClearErrors) {
  const std::filesystem::path dir = std::filesystem::path(VESSEL_FUZZ_CORPUS) / "msh";
  for (const char* name : {"regress_unknown_section_truncated.msh", "regress_short_element_line.msh"}) {
    std::istringstream in(test::read_text(dir / name));
    try {
      (void)parse_msh(in, name);
      ADD_FAILURE() << name << " was accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(name), std::string::npos) << msg;
      EXPECT_TRUE(msg.find("truncated") != std::string::npos ||
                  msg.find("element type 0 is not supported") != std::string::npos)
          << msg;
    }
  }
}
