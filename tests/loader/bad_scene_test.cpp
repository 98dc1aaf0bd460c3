// The corpus of broken scene files (support/bad_scene_corpus.hpp) loaded through the library: each
// must fail with InputError and a message naming the file and the JSON pointer of the fault, never
// a crash. The command-line side is tests/cli/bad_scene_cli_test.cpp; this room starts no
// `stereobench`, so that the sanitizer build needs only the libraries.
#include <gtest/gtest.h>

#include <exception>
#include <string>

#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "support/bad_scene_corpus.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using test::bad_scene::bad_scene_corpus;
using test::bad_scene::BadCase;
using test::ScratchDir;
using test::bad_scene::write_case;

TEST(BadScenes, EveryCaseIsAClearInputError) {
  ScratchDir dir("bad");
  for (const BadCase& bc : bad_scene_corpus()) {
    SCOPED_TRACE(bc.name);
    const auto path = write_case(dir, bc);
    try {
      (void)io::load_gltf(path);
      ADD_FAILURE() << bc.name << ": loaded without error";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path.string()), std::string::npos) << "message does not name the file: " << msg;
      EXPECT_NE(msg.find(bc.expect), std::string::npos) << "expected '" << bc.expect << "' in: " << msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << bc.name << ": wrong exception type: " << e.what();
    }
  }
}

TEST(BadScenes, NonExistentPathAndDirectory) {
  ScratchDir dir("nopath");
  EXPECT_THROW((void)io::load_gltf(dir / "missing.gltf"), InputError);
  EXPECT_THROW((void)io::load_gltf(dir.path()), InputError);
}

}  // namespace
}  // namespace sb
