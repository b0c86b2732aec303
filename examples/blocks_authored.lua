-- blocks_authored.lua — authored blocks inside a fracture tile (Paris et
-- al. 2020, figure 6): an equidimensional 20 m tile in which the user
-- placed three blocks and one fracture. The tile's points inside the
-- authored blocks are removed, the edges across them cut, and generated
-- blocks that reached into them cut back, so the authored blocks (red)
-- sit among the generated ones (grey) with joints all round; the user's
-- fracture, a disc of radius 8 m tilted 30 degrees, cuts the blocks it
-- crosses.
--
--   outcrop run examples/blocks_authored.lua [--seed N] [--out DIR]
--
-- Prints the tile's statistics; writes blocks_authored.png (640 x 360).

local oc = require "outcrop"

-- the half-spaces sx x + sy y + sz z + d <= 0 of |p - c|_1 <= r
local function octahedron(c, r)
  local pl = {}
  for _, sx in ipairs{-1, 1} do
    for _, sy in ipairs{-1, 1} do
      for _, sz in ipairs{-1, 1} do
        pl[#pl + 1] = {sx, sy, sz, -(sx * c[1] + sy * c[2] + sz * c[3]) - r}
      end
    end
  end
  return pl
end

local tile = oc.blocks.tile{
  type = "equidimensional",
  blocks = {
    -- a long box lying along x
    {box = {3, 1, 12, 15, 5, 16}},
    -- a tetrahedron by its corners
    {points = {{11, 1, 1}, {18, 1, 1}, {15, 1, 8}, {15, 6, 3}}},
    -- an octahedron by its eight faces: |x - 5| + |y - 5| + |z - 5| <= 4
    {planes = octahedron({5, 5, 5}, 4)},
  },
  discs = {{center = {10, 10, 10}, normal = {0.5, 0, 0.87}, radius = 8}},
}
local s = tile:stats()
print(string.format("blocks_authored: %d points, %d discs, %d blocks (%d " ..
                    "authored), %.2f s", s.points, s.fractures, s.blocks,
                    s.authored, s.seconds))

-- the authored blocks are the last ones: a colour field 2T inside them
local authored = {}
for i = s.blocks - s.authored + 1, s.blocks do
  authored[#authored + 1] = tile:block(i)
end
local mark = oc.union(authored)
local cube = oc.box{min = {0, 0, 0}, max = {20, 20, 20}, falloff = 0.05}
local scene = oc.intersection{tile:node(), cube}
local palette = {{0.0, {0.55, 0.53, 0.50}}, {0.4, {0.55, 0.53, 0.50}},
                 {0.6, {0.75, 0.22, 0.15}}, {1.0, {0.75, 0.22, 0.15}}}
oc.render(scene, {camera = {eye = {-16, -26, 28}, target = {10, 10, 8}, fov = 40},
                  size = {640, 360}, color = mark, palette = palette})
  :write("blocks_authored.png")
print("blocks_authored: wrote blocks_authored.png")
