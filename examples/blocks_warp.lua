-- blocks_warp.lua — details on an implicit sphere three ways (Paris et
-- al. 2020, figure 12): turbulence added to the field (a hypertexture,
-- left), a radial perturbation of the distance (a star-shaped primitive,
-- middle) and the gradient-based warp by a relief (right), which moves
-- the surface along its normal by the relief seen on the three planes xy,
-- xz, yz.
--
--   outcrop run examples/blocks_warp.lua [--seed N] [--out DIR]
--
-- Writes blocks_warp.png (450 x 150: the hypertexture and the warp have
-- large Lipschitz bounds, so sphere tracing takes small steps; about a
-- minute of CPU).

local oc = require "outcrop"

local function ball(x)
  return oc.sphere{center = {x, 0, 0}, radius = 1, falloff = 0.5}
end

-- turbulence added to the field, centred (t in [0, 2 - 2^-3])
local turb = oc.turbulence{wavelength = 0.35, amplitude = 0.45, octaves = 4,
                           offset = -0.45 * (2 - 2 ^ -3) / 2}
-- (kept near the sphere's surface by an intersection with a larger one)
local hyper = oc.blend{ball(0), oc.intersection{
  turb, oc.sphere{center = {0, 0, 0}, radius = 1.2, falloff = 0.3}}}
local radial = oc.perturb(ball(3), {wavelength = 0.35, amplitude = 0.3,
                                    octaves = 4})
local warped = oc.relief_warp(ball(6), {relief = {wavelength = 0.35,
                                                  octaves = 4},
                                        amplitude = 0.12})
print(string.format("blocks_warp: Lipschitz bounds %.2f (sphere), %.2f " ..
                    "(gradient warp)", ball(0):lipschitz(),
                    warped:lipschitz()))
local scene = oc.union{hyper, radial, warped}
oc.render(scene, {camera = {eye = {3, -7.5, 3}, target = {3, 0, 0}, fov = 45},
                  size = {450, 150}}):write("blocks_warp.png")
print("blocks_warp: wrote blocks_warp.png")
