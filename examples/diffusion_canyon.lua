-- diffusion_canyon.lua — a canyon edited incrementally (Hnaidi et al.
-- 2010, figure 10): the same scene with its first 15, 30 and all 74
-- feature curves, each diffused on a 2 x 2 km grid and rendered.
--   15: the river (its bed falling from 60 to 30 m, banks rising at 10
--       degrees), the two rims at 260 m with 65-degree walls falling
--       towards the river and the plateau level behind them, two benches
--       at 150 m halfway down, the plateau's edges, and eight side
--       canyons cut into the plateau (cracks: slopes only);
--   30: fifteen spurs running from the rims towards the river;
--   74: forty-four small ridges and gullies on the plateau, with noise
--       rougher on the walls than on the plateau.
-- Positions come from a fixed formula, so every run draws the same scene.
--
--   outcrop run examples/diffusion_canyon.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

local function slope(l, r, a, b)
  return {left = l, right = r, extent = {a, b}}
end
-- a fixed sequence in [0, 1)
local seq = 0
local function rnd()
  seq = seq + 1
  local x = math.sin(seq * 12.9898) * 43758.5453
  return x - math.floor(x)
end
-- the river's x at y (the canyon winds south to north)
local function river_x(y) return 1024 + 260 * math.sin(y / 330) end
local function path(dx, n)
  local p = {}
  for i = 0, n do
    local y = -40 + i * 2128 / n
    p[#p + 1] = {river_x(y) + dx, y}
  end
  return p
end

local noise_wall = {amplitude = 6, roughness = 0.8}
local noise_flat = {amplitude = 3, roughness = 0.3}
local curves = {
  oc.feature_curve{points = path(0, 24), constraints = {
    {u = 0, height = 60, radius = 8, slope = slope(-10, -10, 50, 50)},
    {u = 1, height = 30, radius = 8, slope = slope(-10, -10, 50, 50)}}},
  -- west rim: the river is on its right; east rim: on its left
  oc.feature_curve{points = path(-330, 24), constraints = {
    {u = 0, height = 260, radius = 4, slope = slope(0, 65, 200, 70),
     noise = noise_wall},
    {u = 1, height = 270, radius = 4, slope = slope(0, 65, 200, 70),
     noise = noise_wall}}},
  oc.feature_curve{points = path(330, 24), constraints = {
    {u = 0, height = 255, radius = 4, slope = slope(65, 0, 70, 200),
     noise = noise_wall},
    {u = 1, height = 265, radius = 4, slope = slope(65, 0, 70, 200),
     noise = noise_wall}}},
  oc.feature_curve{points = path(-160, 24), constraints = {
    {u = 0, height = 150, radius = 14, slope = slope(0, 55, 30, 40)},
    {u = 1, height = 140, radius = 14, slope = slope(0, 55, 30, 40)}}},
  oc.feature_curve{points = path(160, 24), constraints = {
    {u = 0, height = 145, radius = 14, slope = slope(55, 0, 40, 30)},
    {u = 1, height = 150, radius = 14, slope = slope(55, 0, 40, 30)}}},
  oc.feature_curve{points = path(-1000, 12), constraints = {
    {u = 0, height = 280, noise = noise_flat},
    {u = 1, height = 290, noise = noise_flat}}},
  oc.feature_curve{points = path(1000, 12), constraints = {
    {u = 0, height = 285, noise = noise_flat},
    {u = 1, height = 280, noise = noise_flat}}},
}
-- side canyons into the plateau
for i = 1, 8 do
  local y = 150 + (i - 1) * 250 + 60 * rnd()
  local side = i % 2 == 0 and 1 or -1
  local x0 = river_x(y) + side * 340
  curves[#curves + 1] = oc.feature_curve{
    points = {{x0, y}, {x0 + side * (200 + 150 * rnd()), y + 120 * (rnd() - 0.5)}},
    constraints = {{u = 0, slope = slope(-45, -45, 40, 40)},
                   {u = 1, slope = slope(-30, -30, 15, 15)}}}
end
local counts = {15, 30, 74}
assert(#curves == 15)
-- spurs from the rims towards the river
for i = 1, 15 do
  local y = 80 + (i - 1) * 135 + 40 * rnd()
  local side = i % 2 == 0 and 1 or -1
  local x0 = river_x(y) + side * 320
  curves[#curves + 1] = oc.feature_curve{
    points = {{x0, y}, {river_x(y) + side * (80 + 60 * rnd()), y + 60 * (rnd() - 0.5)}},
    constraints = {
      {u = 0, height = 240, radius = 3, slope = slope(45, 45, 40, 40),
       noise = noise_wall},
      {u = 1, height = 90, radius = 3, slope = slope(35, 35, 30, 30),
       noise = noise_wall}}}
end
-- small ridges and gullies on the plateau
for i = 1, 44 do
  local y = 60 * i - 100 * rnd() + 20
  local side = i % 2 == 0 and 1 or -1
  local x0 = river_x(y) + side * (420 + 450 * rnd())
  local a = 2 * math.pi * rnd()
  local x1, y1 = x0 + 140 * math.cos(a), y + 140 * math.sin(a)
  local up = rnd() < 0.5
  curves[#curves + 1] = oc.feature_curve{points = {{x0, y}, {x1, y1}},
    constraints = {
      {u = 0, height = up and 300 or nil, slope = up and slope(20, 20, 50, 50)
         or slope(-25, -25, 20, 20), noise = noise_flat},
      {u = 1, height = up and 290 or nil, slope = up and slope(20, 20, 50, 50)
         or slope(-25, -25, 20, 20), noise = noise_flat}}}
end
assert(#curves == 74)

for _, n in ipairs(counts) do
  local some = table.move(curves, 1, n, 1, {})
  local hf, maps = oc.diffusion{size = {513, 513}, cell = 4, curves = some,
    converged = true, seed = 2, noise = {wavelength = 120}}
  print(("diffusion_canyon: %d curves, %d steps, %.0f..%.0f m")
        :format(n, maps.cycles, hf:min(), hf:max()))
  local img = oc.render(hf, {size = {w, h},
    camera = {eye = {1024, -1000, 1300}, target = {1024, 1000, 100}, fov = 40}})
  assert(img:write(("diffusion_canyon_%d.png"):format(n)))
end
