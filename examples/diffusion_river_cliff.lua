-- diffusion_river_cliff.lua — a riverbed and a cliff from feature curves
-- (Hnaidi et al. 2010, figure 6). Left: a meandering riverbed, its
-- elevation falling from 70 to 40 m, 10 m wide (the radius of the strict
-- elevation), banks rising at 12 degrees over 90 m (negative slopes: the
-- ground rises away from the curve) between two low ridges. Right: a
-- cliff edge at 160 m, falling at 70 degrees over 60 m on its left side
-- and level (0 degrees) over 150 m on its right: the plateau behind it.
--
--   outcrop run examples/diffusion_river_cliff.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

local function slope(l, r, a, b)
  return {left = l, right = r, extent = {a, b}}
end

local curves = {
  -- the river, south to north on the left half
  oc.feature_curve{points = {{500, -20}, {300, 250}, {700, 450}, {500, 700},
                             {300, 950}, {650, 1000}, {520, 1300}},
    bezier = true, constraints = {
      {u = 0, height = 70, radius = 5, slope = slope(-12, -12, 90, 90)},
      {u = 1, height = 40, radius = 5, slope = slope(-12, -12, 90, 90)}}},
  -- the ridges either side of its valley
  oc.feature_curve{points = {{60, -20}, {60, 1300}}, constraints = {
    {u = 0, height = 140, radius = 4}, {u = 1, height = 120, radius = 4}}},
  oc.feature_curve{points = {{940, -20}, {940, 1300}}, constraints = {
    {u = 0, height = 130, radius = 4}, {u = 1, height = 150, radius = 4}}},
  -- the cliff's edge, south to north on the right half: the face on its
  -- left (west), the plateau on its right (east)
  oc.feature_curve{points = {{1380, -20}, {1300, 400}, {1500, 800}, {1400, 1300}},
    bezier = true, constraints = {
      {u = 0, height = 160, radius = 2, slope = slope(70, 0, 60, 150)},
      {u = 1, height = 170, radius = 2, slope = slope(70, 0, 60, 150)}}},
  -- the foot of the cliff
  oc.feature_curve{points = {{1060, -20}, {1060, 1300}}, constraints = {
    {u = 0, height = 20, radius = 4}, {u = 1, height = 25, radius = 4}}},
}

local hf, maps = oc.diffusion{size = {513, 321}, cell = 4, curves = curves,
  converged = true}
print(("diffusion_river_cliff: %d steps, %.0f..%.0f m"):format(maps.cycles,
      hf:min(), hf:max()))
local img = oc.render(hf, {size = {w, h},
  camera = {eye = {1024, -1500, 1500}, target = {1024, 640, 40}, fov = 40}})
assert(img:write("diffusion_river_cliff.png"))
