#pragma once
// SIGINT, SIGTERM and SIGHUP end matbake cleanly: every temporary file of an output being written
// is removed, finished outputs stay, and the exit status is 128 + the signal, as a shell reports
// for a killed process. The signals are blocked in every thread and taken by one waiting thread,
// so no library code runs inside an asynchronous handler. Call before any thread is started.
namespace matbake::cli {

void remove_temporary_files_on_interrupt();

}  // namespace matbake::cli
