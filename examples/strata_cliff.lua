-- strata_cliff.lua — stratified cliffs and overhangs without primitives
-- (Paris et al. 2019, figure 10): a block of rock whose +x face is eroded by an
-- erosion node reading a geology tree of folded strata, a soft layer and
-- a hard pocket. Soft beds are carved back into the cliff, hard ones stand
-- out as ledges and overhangs.
--
--   outcrop run examples/strata_cliff.lua [--set cell=0.6] [--seed N] [--out DIR]
--
-- Writes strata_cliff.ply (mesh coloured by resistance), strata_cliff_xz.png
-- (cut plane through the cliff coloured by resistance, pale = hard) and
-- strata_cliff_eroded_xz.png (the eroded field on the same plane).

local oc = require "outcrop"

local cell = oc.param("cell", 0.6)
local G = oc.geology

-- The terrain: a block of rock, its cliff face at x = 20.
local rock = oc.box{min = {-40, -30, -30}, max = {20, 30, 25}, falloff = 4}

-- The geology: horizontal strata (noise along z only), folded gently, plus
-- a soft bed at z = 5, a hard pocket under the cliff top; a fault dipping under the
-- cliff shifts everything behind it up by 5 m.
local strata = G.strata{wavelength = 9, octaves = 4, amplitude = 0.9, offset = 0.05}
local soft = G.layer{origin = {0, 0, 5}, normal = {0.05, 0, 1}, radius = 2.5,
                     resistance = -0.5}
local hard = G.sphere{center = {20, 8, 12}, radius = 5, falloff = 5, resistance = 0.6}
local folded = G.fold(strata + soft, {wavelength = 40, amplitude = 5, octaves = 2})
local geology = G.fault(folded + hard,
                        {domain = {origin = {10, 0, 0}, normal = {1, 0, 0.6}},
                         offset = {0, 0, 5}})

-- Erode a band 12 m deep behind the cliff face: the control falls from 1
-- on the face to 0 twelve metres in.
local control = oc.box{min = {20, -40, -40}, max = {40, 40, 40}, falloff = 12}
local cliff = oc.erosion(rock, geology, {control = control, depth = 0.85})

local st = cliff:stats()
print(string.format("strata_cliff: %d nodes, %d primitives, L = %g", st.nodes,
                    st.primitives, cliff:lipschitz()))

local palette = {{0.0, {0.30, 0.18, 0.10}}, {0.4, {0.55, 0.40, 0.26}},
                 {0.7, {0.78, 0.66, 0.48}}, {1.0, {0.96, 0.92, 0.84}}}

local mesh = oc.polygonize(cliff, {box = {-10, -30, -31, 26, 30, 30}, cell = cell,
                                   colors = {field = geology, palette = palette}})
assert(mesh:write("strata_cliff.ply"))
local ms = mesh:stats()
print(string.format("strata_cliff: wrote strata_cliff.ply (%d triangles, %.2f s)",
                    ms.triangles, ms.seconds))

local slice = {plane = "xz", at = 0, box = {-10, -31, 26, 30}, size = {540, 915}}
slice.palette = palette
assert(G.slice(geology, slice):write("strata_cliff_xz.png"))
slice.palette = nil
assert(oc.slice(cliff, slice):write("strata_cliff_eroded_xz.png"))
print("strata_cliff: wrote strata_cliff_xz.png, strata_cliff_eroded_xz.png")
