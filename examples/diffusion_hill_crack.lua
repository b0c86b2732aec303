-- diffusion_hill_crack.lua — a hill and a crack from feature curves
-- (Hnaidi et al. 2010, figure 7). Left: a hill, a short curve at 140 m
-- with level slopes (0 degrees) over 80 m on both sides: a null gradient
-- that holds the ground around it at the same elevation, a rounded top
-- falling by Laplace to the 30 m plain. Right: a crack across a plateau,
-- a curve with no strict elevation and rising slopes (-40 degrees) over
-- 60 m on both sides: its floor is wherever the slopes from the plateau
-- lead (the guide direction is turned towards the curve, as the paper
-- does for curves without elevation).
--
--   outcrop run examples/diffusion_hill_crack.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

local function slope(l, r, a, b)
  return {left = l, right = r, extent = {a, b}}
end

local curves = {
  -- the hill
  oc.feature_curve{points = {{350, 500}, {650, 560}}, constraints = {
    {u = 0, height = 140, radius = 6, slope = slope(0, 0, 80, 80)},
    {u = 1, height = 140, radius = 6, slope = slope(0, 0, 80, 80)}}},
  -- the plain around the hill
  oc.feature_curve{points = {{20, 20}, {980, 20}, {980, 1004}, {20, 1004},
                             {20, 20}},
    constraints = {{u = 0, height = 30}, {u = 1, height = 30}}},
  -- the plateau, held at 120 m by its edges
  oc.feature_curve{points = {{1100, 60}, {1100, 964}}, constraints = {
    {u = 0, height = 120, radius = 8}, {u = 1, height = 120, radius = 8}}},
  oc.feature_curve{points = {{2000, 60}, {2000, 964}}, constraints = {
    {u = 0, height = 125, radius = 8}, {u = 1, height = 125, radius = 8}}},
  -- the crack: slopes only
  oc.feature_curve{points = {{1250, 150}, {1500, 500}, {1700, 560}, {1850, 880}},
    bezier = true, constraints = {
      {u = 0, slope = slope(-40, -40, 60, 60)},
      {u = 1, slope = slope(-40, -40, 60, 60)}}},
}

local hf, maps = oc.diffusion{size = {513, 257}, cell = 4, curves = curves,
  converged = true}
print(("diffusion_hill_crack: %d steps, %.0f..%.0f m"):format(maps.cycles,
      hf:min(), hf:max()))
local img = oc.render(hf, {size = {w, h},
  camera = {eye = {1024, -1300, 1400}, target = {1024, 520, 40}, fov = 40}})
assert(img:write("diffusion_hill_crack.png"))
