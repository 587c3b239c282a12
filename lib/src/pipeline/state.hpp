#pragma once
// Stamps: what each job's last successful run read and wrote, kept in <output>/.matbake/, so a
// job runs again only when an input's content, its options or matbake's version changed, or an
// output is missing or was changed by someone else.
#include <filesystem>
#include <string>
#include <vector>

#include "matbake/pipeline.hpp"

namespace matbake::pipeline {

std::string job_file_stem(const Job& job);  // "material-wood": the stamp's and the depfile's name

// Why the job must run, or empty when it is up to date. An input whose size and modification time
// are as recorded is taken as unchanged; otherwise its content hash decides (a touched file or a
// fresh checkout does not rebuild). With `refresh`, the stamp of an up-to-date job takes the new
// times of such inputs, so that the next run need not hash them again.
std::string out_of_date_reason(const Job& job, const std::filesystem::path& state_folder, bool refresh);

// Records a successful run: the files it read and wrote, as they are now.
Status write_stamp(const Job& job, const std::vector<std::filesystem::path>& read,
                   const std::vector<std::filesystem::path>& written, const std::filesystem::path& state_folder);

// Removes the stamp, so that a failed job runs again next time.
void remove_stamp(const Job& job, const std::filesystem::path& state_folder);

}  // namespace matbake::pipeline
