// SPDX-License-Identifier: GPL-3.0-or-later
// Imported by every test file that starts processes (tests/http/lib.mjs
// imports it for the HTTP tests): nothing a test starts outlives it,
// whatever ends the test (a SIGKILL of node too).
//
// - CONVSIM_TETHER names this node process to every process started from
//   here: the convsim programs end with a SIGKILL when it ends (core/
//   tether.c: the kernel's parent-death signal for a direct child, a
//   watch on the process for one started through make, a shell, mpirun or
//   the daemon).
// - When the process that started this one (node --test's runner, the
//   shell) ends, this one ends too (SIGKILL, 250 ms at most), so that
//   killing the runner ends the test file's process and, with it,
//   everything the file started.
import { readFileSync } from 'node:fs';

// The parent's id as the kernel sees it now (process.ppid keeps the one
// at start); null where there is no /proc.
function parentNow() {
  try {
    const stat = readFileSync('/proc/self/stat', 'utf8');
    return Number(stat.slice(stat.lastIndexOf(')') + 2).split(' ')[1]);
  } catch {
    return null;
  }
}

// (a module runs once per process, however often it is imported)
process.env.CONVSIM_TETHER = String(process.pid);
const parent = parentNow();
if (parent !== null) {
  setInterval(() => {
    if (parentNow() !== parent) process.kill(process.pid, 'SIGKILL');
  }, 250).unref();
}
