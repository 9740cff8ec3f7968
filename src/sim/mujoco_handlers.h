// MuJoCo's error and warning handlers. Without them MuJoCo prints a fatal error on stdout, writes
// MUJOCO_LOG.TXT into the working directory and waits for Enter; with them an error is a
// cradle::UserError ("MuJoCo: ...", one line) thrown where MuJoCo failed (e.g. mj_makeData out of
// memory), and a warning is one line on stderr (never stdout).
#pragma once

namespace cradle::sim {

// Installs both handlers (process-wide in MuJoCo; the first call does it, later calls nothing).
// Called before every model compile and mjData allocation.
void install_mujoco_handlers();

}  // namespace cradle::sim
