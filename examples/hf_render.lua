-- hf_render.lua — a heightfield rendered directly: 2 x 2 km of fBm
-- mountains traced as the surface z = h(x, y) with the accelerated
-- local-Lipschitz tracer of Génevaux et al. 2015 (section 7.2), no
-- implicitization and no mesh; then the same view with plain sphere
-- tracing, to compare the height calls.
--
--   outcrop run examples/hf_render.lua [--set size=960] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 960)
local h = w * 9 // 16

-- 513 x 513 samples 4 m apart, 8 octaves of the engine's turbulence
local hf = oc.heightfield.fbm{size = {513, 513}, cell = 4, origin = {-1024, -1024},
                              wavelength = 900, amplitude = 260, octaves = 8, seed = 14}

local view = {
  size = {w, h},
  camera = {eye = {-1500, -1700, 900}, target = {0, 0, 50}, fov = 40},
}
local img, st = oc.render(hf, view)
assert(img:write("hf_render.png"))
print(("hf_render: wrote hf_render.png, %.1f height calls per pixel (%.1f with shadows and AO)")
      :format(st.calls_per_pixel, st.calls_total_per_pixel))

view.tracer = "sphere"
local _, sp = oc.render(hf, view)
print(("hf_render: plain sphere tracing took %.1f calls per pixel, %.2f x as many")
      :format(sp.calls_per_pixel, sp.calls / st.calls))
