-- blocks_sea_spire.lua — a sea spire made of rock blocks (Paris et al.
-- 2020, figure 3): a cone 50 m high and 16 m in radius standing in the
-- sea, its steep flanks amplified with rhombohedral blocks (the slope
-- criterion leaves the gentler foot smooth).
--
--   outcrop run examples/blocks_sea_spire.lua [--seed N] [--out DIR]
--
-- Prints the instance count; writes blocks_sea_spire.png (360 x 480).

local oc = require "outcrop"

local spire = oc.cone{base = {0, 0, -10}, apex = {0, 0, 50}, radius = 16,
                      falloff = 8}
local tile = oc.blocks.tile{type = "rhombohedral"}
local rock = oc.blocks.replicate(spire, {tiles = {{tile = tile}}, slope = 0.6,
                                         distance = {-2, 2}})
print(string.format("blocks_sea_spire: %d instances", rock:stats().instances))

local sea = oc.box{min = {-60, -60, -20}, max = {60, 60, 0}, falloff = 0.5}
local wet = oc.box{min = {-60, -60, -20}, max = {60, 60, 0.5}, falloff = 0.1,
                   energy = 4}
local palette = {{0.0, {0.45, 0.40, 0.34}}, {1.0, {0.45, 0.40, 0.34}},
                 {1.5, {0.10, 0.25, 0.35}}, {4.0, {0.10, 0.25, 0.35}}}
oc.render(oc.union{rock, sea},
          {camera = {eye = {-55, -70, 30}, target = {0, 0, 20}, fov = 45},
           size = {360, 480}, color = wet, palette = palette,
           sun = {direction = {-0.5, -0.6, 0.6}, intensity = 1.3}})
  :write("blocks_sea_spire.png")
print("blocks_sea_spire: wrote blocks_sea_spire.png")
