-- diffusion_island.lua — a volcanic island from feature curves (Hnaidi et
-- al. 2010, figure 12): the sea floor at -60 m along the border, the
-- coast (0 m, a closed Bézier loop) with beaches rising gently inland,
-- the volcano's rim at 420..460 m with its outer flank at 28 degrees and
-- its inner wall at 40 degrees falling into a crater whose floor is held
-- at 330 m, five ridges running from the rim to the coast, and noise
-- whose amplitude and roughness grow towards the summit.
--
--   outcrop run examples/diffusion_island.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

local function slope(l, r, a, b)
  return {left = l, right = r, extent = {a, b}}
end

-- a closed loop of radius r around (cx, cy), 4 cubic pieces (k = 0.5523
-- makes them a circle), squashed by sx, sy
local function loop(cx, cy, r, sx, sy)
  local k, p = 0.5523 * r, {}
  local q = {{r, 0, 0, k}, {0, r, -k, 0}, {-r, 0, 0, -k}, {0, -r, k, 0}}
  for i = 1, 4 do
    local a, b = q[i], q[i % 4 + 1]
    p[#p + 1] = {cx + a[1] * sx, cy + a[2] * sy}
    p[#p + 1] = {cx + (a[1] + a[3]) * sx, cy + (a[2] + a[4]) * sy}
    p[#p + 1] = {cx + (b[1] - b[3]) * sx, cy + (b[2] - b[4]) * sy}
  end
  p[#p + 1] = {cx + r * sx, cy}
  return p
end

local cx, cy = 1024, 1024
local curves = {
  -- the sea floor
  oc.feature_curve{points = {{8, 8}, {2040, 8}, {2040, 2040}, {8, 2040},
                             {8, 8}},
    constraints = {{u = 0, height = -60}, {u = 1, height = -60}}},
  -- the coast: counter-clockwise, so the sea is on the right
  oc.feature_curve{points = loop(cx, cy, 760, 1.1, 0.9), bezier = true,
    constraints = {
      {u = 0, height = 0, radius = 4, slope = slope(-4, 6, 120, 150),
       noise = {amplitude = 3, roughness = 0.2}},
      {u = 1, height = 0, radius = 4, slope = slope(-4, 6, 120, 150),
       noise = {amplitude = 3, roughness = 0.2}}}},
  -- the rim: the crater on its left (inside), the outer flank on its right
  oc.feature_curve{points = loop(cx + 60, cy + 40, 190, 1, 1), bezier = true,
    constraints = {
      {u = 0, height = 440, radius = 6, slope = slope(40, 28, 90, 260),
       noise = {amplitude = 10, roughness = 0.8}},
      {u = 0.5, height = 460, radius = 6, slope = slope(40, 28, 90, 260),
       noise = {amplitude = 10, roughness = 0.8}},
      {u = 1, height = 440, radius = 6, slope = slope(40, 28, 90, 260),
       noise = {amplitude = 10, roughness = 0.8}}}},
  -- the crater floor
  oc.feature_curve{points = {{cx + 30, cy + 40}, {cx + 90, cy + 40}},
    constraints = {{u = 0, height = 330, radius = 20},
                   {u = 1, height = 330, radius = 20}}},
}
-- ridges from the rim down to the coast
for i = 0, 4 do
  local a = 2 * math.pi * (i + 0.3) / 5
  local x0, y0 = cx + 60 + 200 * math.cos(a), cy + 40 + 200 * math.sin(a)
  local x1, y1 = cx + 700 * math.cos(a + 0.2), cy + 600 * math.sin(a + 0.2)
  curves[#curves + 1] = oc.feature_curve{points = {{x0, y0}, {x1, y1}},
    constraints = {
      {u = 0, height = 400, radius = 3, slope = slope(30, 30, 60, 60),
       noise = {amplitude = 8, roughness = 0.7}},
      {u = 1, height = 40, radius = 3, slope = slope(20, 20, 40, 40),
       noise = {amplitude = 4, roughness = 0.4}}}}
end

local hf, maps = oc.diffusion{size = {513, 513}, cell = 4, curves = curves,
  converged = true, seed = 12, noise = {wavelength = 300}}
print(("diffusion_island: %d curves, %d steps, %.0f..%.0f m")
      :format(#curves, maps.cycles, hf:min(), hf:max()))
local img = oc.render(hf, {size = {w, h},
  camera = {eye = {1024, -900, 1500}, target = {1024, 1100, 60}, fov = 40}})
assert(img:write("diffusion_island.png"))
