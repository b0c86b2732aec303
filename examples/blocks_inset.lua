-- blocks_inset.lua — blocks replicated on a wall (Paris et al. 2020,
-- section 5) with and without an inset: on the left the wall's smooth
-- surface fills the joints between the blocks (inset = 0, the paper's);
-- on the right the wall sinks 0.4 m where blocks are, so the joints stay
-- open.
--
--   outcrop run examples/blocks_inset.lua [--seed N] [--out DIR]
--
-- Prints the instance counts; writes blocks_inset.png (900 x 360).

local oc = require "outcrop"

local tile = oc.blocks.tile{type = "equidimensional", size = 8, radius = 0.4,
                            disc_radius = {2, 3}, spacing = 1}
local parts = {}
for i, inset in ipairs{0, 0.4} do
  local x0 = (i - 1) * 16 -- a multiple of the tile: the same blocks
  -- a 12 m wall facing -y (its surface 1.35 m out with a 3 m falloff)
  local wall = oc.box{min = {x0, 0, 0}, max = {x0 + 12, 8, 10}, falloff = 3}
  local r = oc.blocks.replicate(wall, {tiles = {{tile = tile}}, slope = 0.5,
                                       distance = {-2, 2},
                                       inset = inset})
  print(string.format("blocks_inset: inset %.1f m: %d blocks", inset,
                      r:stats().instances))
  parts[i] = r
end
oc.render(oc.union(parts),
          {camera = {eye = {14, -22, 9}, target = {14, 0, 5}, fov = 40},
           size = {900, 360}}):write("blocks_inset.png")
print("blocks_inset: wrote blocks_inset.png")
