// Pictures of a TeachMyAgent scene drawn with Cairo as the reference draws them: sky, clouds,
// terrain, water, creepers, the agent's parts (head reddening as it drowns or dries), grasped
// sensors in yellow, optional lidar rays and the start flag. The camera follows the head.
#pragma once

#include <cstdint>
#include <vector>

namespace cradle::tma {

class TmaEnv;

// RGB, row 0 at the top, width x height (the reference viewport is 600 x 400 = 20 x 13.3 units;
// other sizes scale it). Throws cradle::UserError for a non-positive or huge size.
void render(const TmaEnv& env, int width, int height, bool draw_lidars,
            std::vector<std::uint8_t>& rgb);

}  // namespace cradle::tma
