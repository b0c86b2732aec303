-- blocks_types.lua — the four block types of Paris et al. 2020 (figure 5,
-- Table 1): one 20 m fracture tile of each, side by side (equidimensional,
-- rhombohedral, polyhedral, tabular, from left to right), each the union
-- of its convex blocks with rounded edges.
--
--   outcrop run examples/blocks_types.lua [--seed N] [--out DIR]
--
-- Prints each tile's statistics; writes blocks_types.png (1000 x 320).

local oc = require "outcrop"

local types = {"equidimensional", "rhombohedral", "polyhedral", "tabular"}
local parts = {}
for i, ty in ipairs(types) do
  local t = oc.blocks.tile{type = ty}
  local s = t:stats()
  print(string.format("blocks_types: %-16s %5d points, %2d discs, %3d " ..
                      "blocks, %.0f points per block, %.2f s", ty,
                      s.points, s.fractures, s.blocks, s.points_per_block,
                      s.seconds))
  -- keep the blocks whose centroid cell is the tile: clip to the cube
  local cube = oc.box{min = {0, 0, 0}, max = {20, 20, 20}, falloff = 0.05}
  local clipped = oc.intersection{t:node(), cube}
  parts[i] = oc.transform(clipped, {translate = {(i - 1) * 26, 0, 0}})
end
local scene = oc.union(parts)

oc.render(scene, {camera = {eye = {49, -58, 42}, target = {49, 10, 8},
                            fov = 46},
                  size = {1000, 320}}):write("blocks_types.png")
print("blocks_types: wrote blocks_types.png")
