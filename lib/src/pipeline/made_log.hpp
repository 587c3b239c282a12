#pragma once
// The files a build made, by job, each with the hash it was written with, kept in
// <output>/.matbake/made.json: a file no current job makes is removed at the end of a full,
// successful run, and only when it is still as matbake wrote it (a file the user put in the output
// folder, or changed there, is never touched).
#include <map>
#include <string>

#include "matbake/output_gate.hpp"
#include "matbake/pipeline.hpp"
#include "state.hpp"

namespace matbake::pipeline {

struct MadeLog {
  using Files = std::map<std::string, std::string>;  // path (relative to the output folder) → content hash
  std::map<std::string, Files> jobs;  // by job name: what its last successful run wrote
  Files stale;  // made by an earlier run, by no job since, not yet removed
  bool operator==(const MadeLog&) const = default;
};

// Held from reading the log to writing it back: runs at once on one output folder (`build --only`
// as Ninja edges or Slurm array tasks) would otherwise each write what they read and lose the
// others' entries. An advisory lock on <output>/.matbake/made.lock, released when the process ends
// however it ends; where the lock cannot be had (a read-only folder) it holds nothing.
class MadeLogLock {
 public:
  explicit MadeLogLock(const StampRoots& roots);
  MadeLogLock(const MadeLogLock&) = delete;
  MadeLogLock& operator=(const MadeLogLock&) = delete;
  ~MadeLogLock();
  const std::string& problem() const { return problem_; }  // the lock is a link: nothing held

 private:
  int fd_ = -1;
  std::string problem_;
};

// Empty when there is none, or when it is not a log matbake wrote (too large, a link, a field of
// the wrong type): then `problem` says why, and the run warns and starts a new log.
MadeLog read_made_log(const StampRoots& roots, std::string& problem);
Status write_made_log(const MadeLog& log, const StampRoots& roots);

// The log after this run: a built job's entry becomes what it wrote; the files it no longer writes,
// and every file of a job the plan no longer has, become stale (unless a current job writes them).
// Returns the names of the jobs the plan no longer has.
std::vector<std::string> record_run(MadeLog& log, const Plan& plan, const Report& report, const StampRoots& roots);

// The stale files, through the gate: removed when `remove` and provably as matbake wrote them, else
// kept in the log; one changed since it was written, gone, or refused by the gate leaves the log
// (and the disk untouched).
StaleOutputs clean_stale(MadeLog& log, const OutputGate& gate, const StampRoots& roots, bool remove);

}  // namespace matbake::pipeline
