-- blocks_sea_cliff.lua — a sea cliff in three styles (Paris et al. 2020,
-- figure 14): one straight cliff 26 m high over the sea, amplified along
-- three stretches by three tiles, from left to right equidimensional,
-- tabular and columnar blocks. A geology of 0.2, 0.5 and 0.8 along x
-- picks the tile of each stretch (its resistance range); the slope
-- criterion keeps the plateau bare.
--
--   outcrop run examples/blocks_sea_cliff.lua [--seed N] [--out DIR]
--
-- Prints the instance count; writes blocks_sea_cliff.png (480 x 270).

local oc = require "outcrop"

local cliff = oc.box{min = {-20, 0, -10}, max = {140, 60, 26}, falloff = 8}
local function stretch(x0, x1, e)
  return oc.box{min = {x0, -20, -50}, max = {x1, 80, 80}, falloff = 0.01,
                energy = e}
end
local geology = oc.blend{stretch(0, 40, 0.2), stretch(40, 80, 0.5),
                         stretch(80, 120, 0.8)}
local tiles = {}
for i, ty in ipairs{"equidimensional", "tabular", "columnar"} do
  local e = 0.3 * i - 0.1
  tiles[i] = {tile = oc.blocks.tile{type = ty}, resistance = {e - 0.1, e + 0.1}}
end
local rock = oc.blocks.replicate(cliff, {tiles = tiles, geology = geology,
                                         slope = 0.5, distance = {-2, 2}})
print(string.format("blocks_sea_cliff: %d instances", rock:stats().instances))

local sea = oc.box{min = {-40, -80, -20}, max = {160, 80, 0}, falloff = 0.5}
local wet = oc.box{min = {-40, -80, -20}, max = {160, 80, 0.5}, falloff = 0.1,
                   energy = 4}
local palette = {{0.0, {0.42, 0.36, 0.30}}, {1.0, {0.42, 0.36, 0.30}},
                 {1.5, {0.10, 0.25, 0.35}}, {4.0, {0.10, 0.25, 0.35}}}
oc.render(oc.union{rock, sea},
          {camera = {eye = {60, -95, 34}, target = {60, 0, 10}, fov = 40},
           size = {480, 270}, color = wet, palette = palette})
  :write("blocks_sea_cliff.png")
print("blocks_sea_cliff: wrote blocks_sea_cliff.png")
