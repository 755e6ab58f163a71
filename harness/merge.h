// `hairbench merge`: one report from the reports of the shards of one command
// (docs/sharding.md). It refuses, with one line naming the file and the field, shards
// that cannot make one sound report: different builds, different scenario definitions,
// reference runs with different bits, duplicate runs, and runs of the plan that no
// shard brought.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace hairbench {

struct ShardReport {
  std::string file;  // as named on the command line, for the messages
  nlohmann::json report;
};

// Reads one shard's report; throws InputError naming the file.
ShardReport read_shard_report(const std::string& file);

// A machine as the merged report names it: host, CPU, worker threads and GPUs of a
// shard's context. Timings are compared only within one machine.
std::string machine_label(const nlohmann::json& context);

// The merged hairbench-report: the plan's runs in the order of the unsharded command,
// each with its shard ("shard": I), the shards' contexts under "merge", the scenarios
// (identical in every shard that ran them). `context` is the merge's own, with the
// shards' GPUs. With `mix_machines` the charts may compare times from different
// machines, and mark where they do. Throws InputError for the refusals above.
nlohmann::json merge_reports(const std::vector<ShardReport>& shards, bool mix_machines);

// The same for `hairbench stress --shard` reports (stress.json): the cells of every axis
// and the degenerate grooms, each axis's first failure decided again over all its cells.
nlohmann::json merge_stress_reports(const std::vector<ShardReport>& shards);

// The same for `hairbench reproduce --shard` reports (reproduce.json): the shards' papers
// in the plan's order, the summary counted again over all of them, each shard's context
// under "merge" (a paper's rows are measured in one process, on one machine).
nlohmann::json merge_reproduce_reports(const std::vector<ShardReport>& shards);

}  // namespace hairbench
