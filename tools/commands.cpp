#include "tools/commands.h"

namespace mvflow::cli {

void add_all_commands(CLI::App& app, Runner& runner) {
  add_info_command(app, runner);
  add_convert_command(app, runner);
  add_refine_command(app, runner);
  add_eval_command(app, runner);
  add_batch_command(app, runner);
  add_slice_command(app, runner);
  add_render_command(app, runner);
  add_heldout_command(app, runner);
  add_synth_command(app, runner);
  add_subdivide_command(app, runner);
  add_hull_command(app, runner);
}

}  // namespace mvflow::cli
