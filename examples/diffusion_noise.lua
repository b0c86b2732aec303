-- diffusion_noise.lua — amplitude and roughness of the noise detail
-- (Hnaidi et al. 2010, figure 8): a 60 m plain (a border curve) with two
-- curves carrying noise constraints only. Left: the amplitude grows from
-- 0 to 30 m along a south-north curve at roughness 0.5. Right: the
-- roughness grows from 0 to 1 at an amplitude of 15 m: at R = 0 the
-- octaves fall as 2^-k (their weights sum to 1.875), at R = 1 they are
-- blended equally (the sum is 4), so the ground turns rough.
--
--   outcrop run examples/diffusion_noise.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

local curves = {
  oc.feature_curve{points = {{10, 10}, {2038, 10}, {2038, 1014}, {10, 1014},
                             {10, 10}},
    constraints = {{u = 0, height = 60}, {u = 1, height = 60}}},
  oc.feature_curve{points = {{500, 40}, {500, 984}}, constraints = {
    {u = 0, radius = 200, noise = {amplitude = 0, roughness = 0.5}},
    {u = 1, radius = 200, noise = {amplitude = 30, roughness = 0.5}}}},
  oc.feature_curve{points = {{1540, 40}, {1540, 984}}, constraints = {
    {u = 0, radius = 200, noise = {amplitude = 15, roughness = 0}},
    {u = 1, radius = 200, noise = {amplitude = 15, roughness = 1}}}},
}

local hf, maps = oc.diffusion{size = {513, 257}, cell = 4, curves = curves,
  seed = 4, noise = {wavelength = 160}}
print(("diffusion_noise: detail %.1f..%.1f m"):format(maps.detail:min(),
      maps.detail:max()))
local img = oc.render(hf, {size = {w, h},
  camera = {eye = {1024, -1300, 1200}, target = {1024, 520, 40}, fov = 40}})
assert(img:write("diffusion_noise.png"))
