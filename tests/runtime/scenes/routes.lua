-- routes.lua HEIGHTMAP: the same outputs by either front end, `outcrop run`
-- or stock lua5.4 with outcrop.configure (run.sh compares them): reads
-- parameters, writes a heightfield, loads HEIGHTMAP, writes a slice and
-- a render.
local oc = require "outcrop"
local steps = oc.param("steps", 4)
local size = oc.param("size", 24)
local bumps = oc.heightfield.fbm{size = {size, size}, wavelength = 6,
  amplitude = steps}
assert(bumps:save("bumps.png"))
local hf = oc.heightfield.load(arg[1], {cell = 1})
local t = oc.terrain(hf)
local scene = t + oc.turbulence{wavelength = 3, amplitude = 0.1}
assert(oc.slice(scene, {size = {size, size}, plane = "xy", at = 2,
  box = {0, 0, 15, 15}}):write("slice.png"))
assert(oc.render(oc.point{center = {0, 0, 0}, radius = steps},
  {size = {size, size}, camera = {eye = {10, -10, 8}, target = {0, 0, 0}}})
  :write("render.exr"))
print("routes", steps, size)
