-- diffusion_ridges.lua — a ridge line and multiple ridge lines from feature
-- curves (Hnaidi et al. 2010, figure 5). Left: one curve carrying its
-- crest elevation (a natural spline through three heights) and slopes of
-- 35 and 25 degrees on its two sides. Right: three ridges meeting at a
-- common 320 m peak, each with its own slopes; where their flanks overlap
-- the gradients conflict, are left empty and filled by diffusion. The
-- rest of the 2 x 1 km grid is Laplace, held at 20 m by a boundary curve.
--
--   outcrop run examples/diffusion_ridges.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

local function slope(l, r, a, b)
  return {left = l, right = r, extent = {a, b}}
end

local curves = {
  -- the single ridge, west to east across the left half
  oc.feature_curve{points = {{120, 260}, {300, 420}, {600, 620}, {880, 700}},
    bezier = true, constraints = {
      {u = 0, height = 120, radius = 4, slope = slope(35, 25, 220, 220)},
      {u = 0.45, height = 260, radius = 4, slope = slope(35, 25, 220, 220)},
      {u = 1, height = 150, radius = 4, slope = slope(35, 25, 220, 220)}}},
}
-- three ridges from the peak at (1500, 520)
for _, r in ipairs{{1180, 260, 30}, {1850, 300, 40}, {1560, 900, 25}} do
  curves[#curves + 1] = oc.feature_curve{points = {{1500, 520}, {r[1], r[2]}},
    constraints = {
      {u = 0, height = 320, radius = 3, slope = slope(r[3], r[3], 260, 260)},
      {u = 1, height = 90, radius = 3, slope = slope(r[3], r[3], 120, 120)}}}
end
-- the plain around: a low closed curve along the border
curves[#curves + 1] = oc.feature_curve{
  points = {{5, 5}, {2043, 5}, {2043, 1019}, {5, 1019}, {5, 5}},
  constraints = {{u = 0, height = 20}, {u = 1, height = 20}}}

local hf, maps = oc.diffusion{size = {513, 257}, cell = 4, curves = curves,
  converged = true}
print(("diffusion_ridges: %d steps, %d strict, %d slope and %d conflicting "
      .. "samples, %.0f..%.0f m"):format(maps.cycles, maps.strict, maps.slope,
      maps.conflict, hf:min(), hf:max()))
local img = oc.render(hf, {size = {w, h},
  camera = {eye = {1024, -650, 1500}, target = {1024, 520, 80}, fov = 40}})
assert(img:write("diffusion_ridges.png"))
