-- blocks_canyon.lua — a canyon amplified with rock blocks (Paris et al.
-- 2020, figure 11): equidimensional blocks at the bottom of the walls,
-- tabular blocks on their higher parts, none on the plateau or the floor.
-- The terrain is two plateaus 36 m high with a floor between them (boxes
-- with an 8 m falloff, so the distance estimate holds over a block); the
-- geology is 1 (hard) below 14 m and 0.5 (bedded) above, and each tile
-- is given its resistance range; the slope criterion keeps the flat
-- ground bare.
--
--   outcrop run examples/blocks_canyon.lua [--seed N] [--out DIR]
--
-- Prints the instance counts; writes blocks_canyon.png (480 x 270).

local oc = require "outcrop"

local L = 60 -- length of the canyon along x
local walls = oc.union{
  oc.box{min = {-20, -30, -10}, max = {L + 20, 10, 36}, falloff = 8},
  oc.box{min = {-20, 24, -10}, max = {L + 20, 60, 36}, falloff = 8},
  oc.box{min = {-20, -30, -10}, max = {L + 20, 60, 0}, falloff = 8}}
-- resistance: 1 below 14 m, 0.5 above, 0 outside the part shown
local geology = oc.blend{
  oc.box{min = {0, -30, -50}, max = {L, 60, 14}, falloff = 0.01},
  oc.box{min = {0, -30, 14}, max = {L, 60, 80}, falloff = 0.01, energy = 0.5}}
local hard = oc.blocks.tile{type = "equidimensional"}
local bedded = oc.blocks.tile{type = "tabular"}
local rock = oc.blocks.replicate(walls, {
  tiles = {{tile = hard, resistance = {0.9, 2}},
           {tile = bedded, resistance = {0.4, 0.6}}},
  geology = geology, slope = 0.5, distance = {-2, 2}})
print(string.format("blocks_canyon: %d instances", rock:stats().instances))

-- colour: the geology (dark below, light above)
local palette = {{0.0, {0.40, 0.30, 0.22}}, {0.5, {0.55, 0.42, 0.30}},
                 {1.0, {0.30, 0.18, 0.12}}}
-- the near plateau cut away: the far wall seen across the canyon
local view = oc.intersection{rock, oc.box{min = {0, 15, -10},
                                          max = {L, 60, 60}, falloff = 0.05}}
oc.render(view, {camera = {eye = {L / 2, -38, 30}, target = {L / 2, 24, 16},
                           fov = 50},
                 size = {480, 270}, color = geology, palette = palette})
  :write("blocks_canyon.png")
print("blocks_canyon: wrote blocks_canyon.png")
