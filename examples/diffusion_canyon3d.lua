-- diffusion_canyon3d.lua — a diffused canyon amplified in 3D: feature
-- curves (Hnaidi et al. 2010) sketch a 300 m canyon — a river whose bed
-- falls from 12 to 4 m, two rims at 50 m with 60-degree walls falling
-- towards it and the plateau level behind them — the diffused heightfield
-- is implicitized (outcrop.terrain), given horizontal strata, and the
-- river generator of Paris et al. 2019 undercuts its walls where the beds
-- are soft, as examples/canyon.lua does to a hand-written grid.
--
--   outcrop run examples/diffusion_canyon3d.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local G = oc.geology

local w = oc.param("size", 640)
local h = w * 9 // 16

local function slope(l, r, a, b)
  return {left = l, right = r, extent = {a, b}}
end
-- the river's x at y, as in examples/canyon.lua
local function path(dx)
  local p = {}
  for i = 0, 20 do
    local y = -20 + i * 17
    p[#p + 1] = {150 + 35 * math.sin(y / 45) + 10 * math.sin(y / 17) + dx, y}
  end
  return p
end

local curves = {
  oc.feature_curve{points = path(0), constraints = {
    {u = 0, height = 12, radius = 3, slope = slope(-8, -8, 8, 8)},
    {u = 1, height = 4, radius = 3, slope = slope(-8, -8, 8, 8)}}},
  oc.feature_curve{points = path(-26), constraints = {
    {u = 0, height = 50, radius = 1, slope = slope(0, 60, 60, 22),
     noise = {amplitude = 0.6, roughness = 0.4}},
    {u = 1, height = 50, radius = 1, slope = slope(0, 60, 60, 22),
     noise = {amplitude = 0.6, roughness = 0.4}}}},
  oc.feature_curve{points = path(26), constraints = {
    {u = 0, height = 50, radius = 1, slope = slope(60, 0, 22, 60),
     noise = {amplitude = 0.6, roughness = 0.4}},
    {u = 1, height = 50, radius = 1, slope = slope(60, 0, 22, 60),
     noise = {amplitude = 0.6, roughness = 0.4}}}},
}
local ground, maps = oc.diffusion{size = {201, 201}, cell = 1.5, curves = curves,
  converged = true, seed = 8, noise = {wavelength = 40}}
print(("diffusion_canyon3d: %d steps, %.1f..%.1f m"):format(maps.cycles,
      ground:min(), ground:max()))
local terrain = oc.terrain(ground)

-- beds 5 m thick of alternating resistance, a soft one above the floor
local rock = G.strata{wavelength = 5, octaves = 3, amplitude = 0.7, offset = 0.3, seed = 6}
  + G.layer{origin = {0, 0, 16}, normal = {0, 0, 1}, radius = 3, resistance = -0.4}
local scene, info = oc.generate.river{heightfield = ground, terrain = terrain,
                                      geology = rock, radius = 5, spacing = 1.6,
                                      banks = 4, depth = 16, strength = 1.6,
                                      steps = 2}
print(("diffusion_canyon3d: %d primitives carved"):format(info.primitives))

local palette = {{0.0, {0.45, 0.20, 0.10}}, {0.5, {0.66, 0.38, 0.22}},
                 {1.0, {0.85, 0.70, 0.52}}}
oc.render(scene, {camera = {eye = {178, 15, 85}, target = {160, 165, 5}, fov = 45},
                  size = {w, h}, color = rock, palette = palette,
                  sun = {direction = {0.4, -0.3, 0.8}, intensity = 1.6}})
  :write("diffusion_canyon3d.png")
