-- layers_canyon.lua — material stacks (Peytavie et al. 2009, figure 22):
-- a canyon whose cliffs shed rocks. The canyon is a heightfield (a
-- plateau cut by a winding gorge with steep walls) turned into bedrock
-- stacks; the erosion tool turns the top of the cliffs' bedrock into sand
-- and rocks (volume conserved), which fall and settle at their angles of
-- repose as screes at the foot of the walls; the rocks layer is then
-- filled with rocks from a tile of eroded Voronoi cells (section 5),
-- placed where the layer is and culled below twice the largest rock
-- radius.
--
--   outcrop run examples/layers_canyon.lua [--set cell=0.5] [--out DIR]

local oc = require "outcrop"

local cell = oc.param("cell", 0.5)
local T = oc.threshold
local nx, ny = math.floor(80 / cell) + 1, math.floor(48 / cell) + 1

-- a plateau at 24 m cut by a gorge winding along x, 10 m wide at its
-- floor (z = 4), with walls steeper than any angle of repose
local function gorge(x, y)
  local c = 24 + 6 * math.sin(x / 14)
  local d = math.abs(y - c)
  local w = math.max(0, math.min(1, (d - 5) / 7))
  return 4 + 20 * w * w * (3 - 2 * w) + 0.6 * math.sin(0.7 * x + 0.3 * y)
end
local hf = oc.heightfield.from(gorge, {size = {nx, ny}, cell = cell})
local s = oc.layers.from_heightfield(hf, {base = -2})

-- the walls crumble: in patches of the steep walls, the top 2 m of the
-- bedrock turned into 30 % sand and 70 % rocks (volume conserved), then
-- everything stabilised: the debris slides to the foot of the walls
local t0 = os.clock()
local turned, patches = 0, 0
for j = 0, ny - 1 do
  for i = 0, nx - 1 do
    local x, y = i * cell, j * cell
    local c = 24 + 6 * math.sin(x / 14)
    local d = math.abs(y - c)
    local patch = math.sin(0.45 * x + 1.3 * math.floor(y / 8)) > 0.1
    if d > 6.5 and d < 10.5 and patch then
      turned = turned + s:erode{region = {x - 0.1 * cell, y - 0.1 * cell,
                                          x + 0.1 * cell, y + 0.1 * cell},
                                ratio = 0.3, depth = 2, stabilize = false}
      patches = patches + 1
    end
  end
end
local res = s:stabilize{tolerance = 0.005}
print(string.format("layers_canyon: %d x %d stacks, %.0f m^3 of bedrock " ..
                    "in %d stacks turned to sand and rocks, stabilised in " ..
                    "%d passes (%.2f s CPU)", nx, ny, turned, patches,
                    res.iterations, os.clock() - t0))
print(string.format("layers_canyon: sand %.0f m^3, rocks %.0f m^3",
                    s:volume("sand"), s:volume("rocks")))

t0 = os.clock()
local tile = oc.layers.rocks{size = 5, radius = 1.1, seed = 22}
local ground = s:field{materials = {"bedrock", "sand"}, sigma = 2 * cell}
local scene, info = s:rocks(tile, {ground = ground})
print(string.format("layers_canyon: %d rocks in the tile, %d placed " ..
                    "(depth %.2f m) in %.2f s CPU", tile:count(),
                    info.instances, info.depth, os.clock() - t0))

local sand = s:field{materials = {"sand"}}
local function color(x, y, z)
  local p = {x, y, z}
  if ground:eval(p) < 0.8 * T then return 0.17, 0.15, 0.14 end
  if sand:eval(p) > 0.5 * T then return 0.50, 0.36, 0.19 end
  return 0.36, 0.20, 0.12
end
oc.render(scene, {camera = {eye = {-12, 22, 44}, target = {38, 24, 2}, fov = 42},
                  size = {800, 450}, sun = {direction = {0.3, -0.6, 0.74}},
                  color = color}):write("layers_canyon.png")
print("layers_canyon: wrote layers_canyon.png")
