// `stereobench reference generate|verify|update|list`: the reference store of DESIGN §6.4.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "reference/store.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ReferenceArgs {
  std::string store = reference::default_store_dir().string();
  std::string scenes_dir;
  int threads = 0;
  // generate
  std::string scene = "box-wall";
  std::string truth = "full";
  std::optional<int> lights;
  RigCli rig;
  // verify / update
  std::vector<std::string> ids;
  bool no_render = false;
  double min_psnr = INFINITY;
  bool only_failing = false;
  std::string json_out;
  std::string command_line;
};

/// The entries named on the command line, each checked to be one the store holds, or all of them.
std::vector<std::string> chosen_ids(const reference::ReferenceStore& store, const std::vector<std::string>& ids) {
  std::vector<std::string> all = store.ids();
  for (size_t i = 0; i < ids.size(); ++i) {
    store.require(ids[i]);
    if (std::find(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(i), ids[i]) != ids.begin() + static_cast<std::ptrdiff_t>(i))
      throw InputError(fmt::format("reference '{}' is named twice; name each entry once", ids[i]));
  }
  if (!ids.empty()) return ids;
  if (all.empty()) throw InputError(fmt::format("the reference store {} is empty; run `stereobench reference generate`",
                                                store.root().string()));
  return all;
}

void run_generate(const ReferenceArgs& a) {
  const reference::ReferenceStore store(a.store);
  const reference::ReferenceSpec spec{a.scene, a.lights, a.rig.overrides(), a.truth};
  const Executor executor(checked_threads(a.threads));
  const std::string id = store.generate(spec, a.scenes_dir, a.command_line, executor);
  fmt::print("wrote {}\n", (store.root() / id).string());
}

/// Verifies the chosen entries, prints one line each, and returns the results.
std::vector<reference::VerifyResult> verify_all(const ReferenceArgs& a, const reference::ReferenceStore& store) {
  if (!(a.min_psnr > 0.0))
    throw InputError(fmt::format("--min-psnr {} is not a PSNR in dB; give a positive value (e.g. 60), or leave it "
                                 "out to demand identical images",
                                 a.min_psnr));
  const Executor executor(checked_threads(a.threads));
  const reference::VerifyOptions options{!a.no_render, a.min_psnr};
  std::vector<reference::VerifyResult> results;
  for (const std::string& id : chosen_ids(store, a.ids)) {
    results.push_back(store.verify(id, a.scenes_dir, options, executor));
    const reference::VerifyResult& r = results.back();
    fmt::print("{:<14} {}: {}\n", reference::to_string(r.status), r.id, r.detail);
  }
  return results;
}

/// Exit status of a verification: 2 when a reference failed, 4 when some could not be checked
/// because a tool is missing or failed, else 0.
int verdict(const std::vector<reference::VerifyResult>& results) {
  bool failed = false, unavailable = false;
  for (const auto& r : results) {
    if (r.status == reference::Status::unavailable) unavailable = true;
    else if (reference::failed(r.status)) failed = true;
  }
  if (failed) return static_cast<int>(ExitCode::gate_failure);
  if (unavailable) return static_cast<int>(ExitCode::environment);
  return 0;
}

int run_verify(const ReferenceArgs& a) {
  if (a.json_out == "-")
    throw InputError("--json -: reference verify writes its verdicts to a file (standard output shows one line per "
                     "reference); give a file name");
  const reference::ReferenceStore store(a.store);
  if (!a.json_out.empty()) {
    // Inside the store the verdicts could replace a reference's own files.
    std::error_code ec;
    const fs::path out = fs::weakly_canonical(fs::absolute(a.json_out, ec), ec);
    const fs::path root = fs::weakly_canonical(fs::absolute(store.root(), ec), ec);
    const fs::path rel = out.lexically_relative(root);
    if (!rel.empty() && *rel.begin() != "..")
      throw InputError(fmt::format("--json {} lies inside the reference store {}; write the verdicts outside it",
                                   a.json_out, store.root().string()));
    // An earlier run's verdicts must not outlive a run that stops, nor one whose file cannot be
    // written be found out only after every reference was rendered again.
    remove_earlier_output(a.json_out, "--json");
    prepare_output_file_folder(a.json_out, "--json");
  }
  const std::vector<reference::VerifyResult> results = verify_all(a, store);
  if (!a.json_out.empty()) {
    json j = json::array();
    for (const auto& r : results)
      j.push_back({{"id", r.id}, {"status", reference::to_string(r.status)}, {"detail", r.detail},
                   {"bit_identical", r.bit_identical},
                   {"metrics", r.metrics ? validation::to_json(*r.metrics) : json(nullptr)}});
    write_option_file("--json", a.json_out, io::json_text(j, 2) + "\n");
  }
  const int code = verdict(results);
  // What to do differs: a failed check is rewritten by update, unless the entry's spec is lost with
  // its provenance (its line says to remove it and generate it again); an unchecked one needs its tool.
  size_t failures = 0, specless = 0, unchecked = 0;
  for (const auto& r : results) {
    if (r.status == reference::Status::unavailable) {
      ++unchecked;
    } else if (reference::failed(r.status)) {
      ++failures;
      try {
        (void)store.spec_of(r.id);
      } catch (const InputError&) {
        ++specless;
      }
    }
  }
  std::string tail;
  // The command to run as it stands: with the store and scenes folder this run was given.
  const std::string update = "stereobench reference update --only-failing" + store.store_option() +
                             reference::ReferenceStore::scenes_dir_option(a.scenes_dir);
  if (failures > specless)
    tail += fmt::format("; {} did not (rewrite them with `{}`)", failures - specless, update);
  if (specless > 0)
    tail += fmt::format("; {} lost their spec with their provenance (remove each and make it again with `stereobench "
                        "reference generate`, see above)",
                        specless);
  if (unchecked > 0)
    tail += fmt::format("; {} could not be checked here (their tool is missing or failed, see above: install or "
                        "mend it, and verify again)",
                        unchecked);
  fmt::print("{} of {} reference(s) verified{}\n", results.size() - failures - unchecked, results.size(), tail);
  return code;
}

int run_update(const ReferenceArgs& a) {
  if (a.no_render && !a.only_failing)
    throw InputError("--no-render only shapes the check of --only-failing (hashes only); update always renders the "
                     "references it rewrites: add --only-failing, or drop --no-render");
  if (!std::isinf(a.min_psnr) && !a.only_failing)
    throw InputError(fmt::format("--min-psnr {} only shapes the check of --only-failing (which references count as "
                                 "failing); without it every chosen reference is rewritten: add --only-failing, or "
                                 "drop --min-psnr",
                                 a.min_psnr));
  const reference::ReferenceStore store(a.store);
  const Executor executor(checked_threads(a.threads));
  std::vector<std::string> targets;
  // Entries whose check or render needs a tool that is missing or fails: the others are still
  // rewritten, then the run exits 4.
  std::vector<std::string> unchecked, tool_failed;
  if (a.only_failing) {
    for (const reference::VerifyResult& r : verify_all(a, store)) {
      if (r.status == reference::Status::unavailable)
        unchecked.push_back(fmt::format("{} ({})", r.id, r.detail));
      else if (reference::failed(r.status))
        targets.push_back(r.id);
    }
  } else {
    targets = chosen_ids(store, a.ids);
  }
  // An entry whose spec cannot be read, or whose scene is gone, cannot be made again: named, and
  // the others still rewritten.
  std::vector<std::string> unreadable, unrenderable;
  // Folders whose spec makes a reference of another id: that one is written, the folder stays.
  std::vector<std::string> misnamed;
  size_t written_count = 0;
  for (const std::string& id : targets) {
    reference::ReferenceSpec spec;
    try {
      spec = store.spec_of(id);
    } catch (const InputError& e) {
      unreadable.push_back(fmt::format("{} ({})", id, e.what()));
      continue;
    }
    std::string written;
    try {
      written = store.generate(spec, a.scenes_dir, a.command_line, executor);
    } catch (const InputError& e) {
      unrenderable.push_back(fmt::format("{} ({})", id, e.what()));
      continue;
    } catch (const ToolError& e) {
      tool_failed.push_back(fmt::format("{} ({})", id, e.what()));
      continue;
    }
    fmt::print("updated {}\n", (store.root() / written).string());
    ++written_count;
    if (written != id) misnamed.push_back(fmt::format("{} (its spec's reference was written to {})", id, written));
  }
  fmt::print("{} reference(s) rewritten\n", written_count);
  std::vector<std::string> problems;
  if (!unreadable.empty())
    problems.push_back(fmt::format("{} reference(s) could not be rewritten, their provenance gives no spec to render "
                                   "them from; remove each and run `stereobench reference generate` with its "
                                   "scene and rig:\n  {}",
                                   unreadable.size(), fmt::join(unreadable, "\n  ")));
  if (!unrenderable.empty())
    problems.push_back(fmt::format("{} reference(s) could not be rendered again from their spec; mend what each "
                                   "reason names (a scene file gone, another --scenes-dir, an entry of another "
                                   "scene or rig under that id), or remove the entry:\n  {}",
                                   unrenderable.size(), fmt::join(unrenderable, "\n  ")));
  if (!misnamed.empty())
    problems.push_back(fmt::format("{} folder(s) of the store are not named by the id their spec makes, so the "
                                   "rewritten reference lies under its own id and the folder is unchanged; remove "
                                   "each folder:\n  {}",
                                   misnamed.size(), fmt::join(misnamed, "\n  ")));
  // Every kind is named in one message; a missing or failing tool makes it exit 4, the others 3.
  if (!unchecked.empty())
    problems.push_back(fmt::format("{} reference(s) could not be checked, so not updated, because their tool is "
                                   "missing or failed; install or mend it and run the update again:\n  {}",
                                   unchecked.size(), fmt::join(unchecked, "\n  ")));
  if (!tool_failed.empty())
    problems.push_back(fmt::format("{} reference(s) could not be rewritten because their tool is missing or failed; "
                                   "install or mend it and run the update again:\n  {}",
                                   tool_failed.size(), fmt::join(tool_failed, "\n  ")));
  if (problems.empty()) return 0;
  const std::string message = fmt::format("{}", fmt::join(problems, "\n"));
  if (!unchecked.empty() || !tool_failed.empty()) throw ToolError(message);
  throw InputError(message);
}

void run_list(const ReferenceArgs& a) {
  const reference::ReferenceStore store(a.store);
  const std::vector<std::string> ids = store.ids();
  fmt::print("{} reference(s) in {}\n", ids.size(), store.root().string());
  size_t damaged = 0;
  for (const std::string& id : ids) {
    json p;
    try {
      p = store.provenance(id);
    } catch (const InputError& e) {
      // Listed with the damage, so that the listing stays whole; verify reports it as corrupt.
      fmt::print("  {:<48} damaged: {}\n", id, e.what());
      ++damaged;
      continue;
    }
    // A field of another type reads as unknown: the listing is not where damage is judged.
    const auto text = [](const json& o, const char* key) {
      return o.is_object() && o.contains(key) && o[key].is_string() ? o[key].get<std::string>() : std::string("?");
    };
    const json provider = p.is_object() && p.contains("provider") ? p["provider"] : json();
    fmt::print("  {:<48} {:<22} {}\n", id, text(provider, "tool_version"), text(p, "date"));
  }
  if (damaged > 0)
    fmt::print(stderr, "{} of {} reference(s) damaged; `stereobench reference verify` checks them all\n", damaged,
               ids.size());
}

}  // namespace

void register_reference_command(CLI::App& root, const std::string& command_line) {
  auto a = std::make_shared<ReferenceArgs>();
  a->command_line = command_line;
  CLI::App* ref = root.add_subcommand(
      "reference",
      "Reference images with provenance (DESIGN §6.4): ground-truth right eyes stored as EXR with a\n"
      "provenance.json (provider and tool version, scene hash, rig, command line, date, image hash)");
  ref->require_subcommand(1);
  // Options every subcommand takes (after its name).
  const auto add_common = [&](CLI::App* c) {
    c->add_option("--store", a->store, "The reference store folder")->capture_default_str();
    c->add_option("--threads,-t", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
    add_scenes_dir_option(*c, a->scenes_dir);
  };

  CLI::App* gen = ref->add_subcommand(
      "generate",
      "Render a reference right eye and store it under an id of the scene file's name, provider, size, interaxial "
      "(0.1 mm) and convergence (3 digits), with the field of view and light count where they are not the scene's; "
      "an entry of that id made from the same scene and rig is replaced, one made from another is refused");
  add_common(gen);
  gen->add_option("--scene,-s", a->scene, "Scene file (.gltf/.glb) or built-in scene name")->capture_default_str();
  gen->add_option("--truth", a->truth, "Provider: full, blender or povray")->capture_default_str();
  add_lights_option(*gen, a->lights);
  a->rig.add_to(*gen);
  gen->callback([a] { run_generate(*a); });

  const auto add_selection = [&](CLI::App* c) {
    add_common(c);
    c->add_option("ids", a->ids, "Reference ids (default: every reference in the store)");
    c->add_flag("--no-render", a->no_render,
                "Check hashes only (image file and scene), do not render again (update: with --only-failing)");
    c->add_option("--min-psnr", a->min_psnr,
                  "Accept a new render this close to the stored one (dB, 8-bit sRGB); default: identical");
  };
  CLI::App* ver = ref->add_subcommand(
      "verify",
      "Re-hash each reference and its scene, render it again and report drift. Exit 0 when all hold,\n"
      "2 when any drifted, is corrupt or its scene changed, 4 when a provider's tool is missing or failed");
  add_selection(ver);
  ver->add_option("--json", a->json_out, "Also write the verdicts as JSON to this file");
  ver->callback([a] { throw VerdictExit{run_verify(*a)}; });

  CLI::App* upd = ref->add_subcommand("update", "Render references again and rewrite them");
  add_selection(upd);
  upd->add_flag("--only-failing", a->only_failing, "Verify first and rewrite only the references that failed");
  upd->callback([a] { throw VerdictExit{run_update(*a)}; });

  CLI::App* list = ref->add_subcommand("list", "List the stored references");
  add_common(list);
  list->callback([a] { run_list(*a); });
}

}  // namespace sb::cli
