#pragma once
// A stand-in for Slurm's sbatch, for the tests of `plan --format slurm`.
#include <filesystem>
#include <string>
#include <vector>

namespace matbake::test {

// Writes dir/sbatch: it records each call's arguments (one line, tab-separated, in dir/sbatch.log),
// runs the job at once (an array's tasks one by one, with SLURM_ARRAY_TASK_ID) and prints a job id
// from 101 on.
std::filesystem::path stand_in_sbatch(const std::filesystem::path& dir);

// The calls dir/sbatch recorded, each as its arguments.
std::vector<std::vector<std::string>> sbatch_calls(const std::filesystem::path& dir);

}  // namespace matbake::test
