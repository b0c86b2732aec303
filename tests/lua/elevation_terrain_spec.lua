-- elevation_terrain_spec.lua — elevation trees (Génevaux et al. 2015) as
-- terrains and grids: outcrop.terrain(e) has its surface at z = f on
-- Omega_T and no solid off it, takes the heightfield options and a
-- domain, joins 3D nodes, the erosion node and the sea-erosion generator;
-- outcrop.heightfield.from(e) gives e:eval's f at every sample (as
-- floats), holes where asked, the same bytes on 1 and 2 threads;
-- outcrop.polygonize meshes it with its top on f; bad input names the
-- field and the script line; hoodoos and karst grow on a tree too.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "elevation_terrain_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local E = oc.elevation

local rng_state = 2015
local function rand(lo, hi)
  rng_state = (rng_state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * rng_state / 2147483648
end

local function f32(x) return (string.unpack("f", string.pack("f", x))) end

-- Two hills 800 m apart with a gap between them (alpha < 1/2) and a
-- river replaced across the west one.
local west = E.disc{center = {-400, 0}, radius = 600, height = 100,
                    noise = {amplitude = 30, wavelength = 200, octaves = 4}}
local east = E.disc{center = {400, 0}, radius = 600, height = 220,
                    noise = {kind = "ridged", amplitude = 60, wavelength = 250,
                             octaves = 4}}
local river = E.river{points = {{-400, -300, 90}, {-420, 0, 92}, {-380, 300, 95}}}
local scene = E.replace(E.blend{west, east}, river)

describe("outcrop.terrain of an elevation tree", function()
  local t = oc.terrain(scene)

  it("has its surface at z = f on Omega_T and nothing solid off it", function()
    local on, off = 0, 0
    for _ = 1, 3000 do
      local x, y = rand(-700, 700), rand(-300, 300)
      local f, a = scene:eval(x, y)
      if a > 0.5 + 1e-9 then
        R.close(t:eval{x, y, f}, 0.5, 1e-9, "field at z = f")
        assert.is_true(t:eval{x, y, f - 0.01} > 0.5)
        assert.is_true(t:eval{x, y, f + 0.01} < 0.5)
        on = on + 1
      elseif a < 0.5 then
        for z = -100, 400, 9.7 do
          assert.is_true(t:eval{x, y, z} < 0.5)
        end
        off = off + 1
      end
    end
    assert.is_true(on > 800, on .. " samples on Omega_T")
    assert.is_true(off > 300, off .. " samples off it")
  end)

  it("spans the terrain box by default, the domain when given", function()
    local x0, y0, _, x1, y1 = t:bounds()
    -- the terrain box holds Omega_T: the two hills' cores, not the gap's
    -- far corners (weights of 0.4542 r around each centre, and more)
    assert.is_true(x0 < -400 - 0.4542 * 600 and x1 > 400 + 0.4542 * 600)
    assert.is_true(x0 > -1000 and x1 < 1000 and y0 > -600 and y1 < 600)
    local d = oc.terrain(scene, {domain = {-500, -100, 300, 200}})
    local a0, b0, _, a1, b1 = d:bounds()
    assert.are.same({-500, -100, 300, 200}, {a0, b0, a1, b1})
    -- open edges: cut at the domain's sides
    local f = scene:eval(-350, 0)
    assert.is_true(d:eval{-350, 0, f - 1} > 0.5)
    assert.are.equal(0, d:eval{-501, 0, f - 1})
  end)

  it("takes falloff, thickness and invert as heightfield terrains do", function()
    local _, _, z0 = t:bounds()
    -- default falloff: 1/100 of the domain's longer side
    local x0, _, _, x1 = t:bounds()
    local R1 = 0.01 * (x1 - x0)
    local _, _, z2 = oc.terrain(scene, {falloff = 2 * R1}):bounds()
    R.close(z0 - z2, R1, 1e-9, "the prism's floor moves by the falloff")
    local _, _, z3 = oc.terrain(scene, {thickness = 50}):bounds()
    R.close(z0 - z3, 50, 1e-9, "thickness")
    local up = oc.terrain(scene, {invert = true, thickness = 30})
    local f = scene:eval(300, 50)
    assert.is_true(up:eval{300, 50, f + 1} > 0.5)
    assert.is_true(up:eval{300, 50, f - 1} < 0.5)
  end)

  it("joins 3D nodes and the erosion node like any terrain", function()
    local f = scene:eval(400, 0)
    local blob = t + oc.sphere{center = {400, 0, f + 20}, radius = 10}
    assert.is_true(blob:eval{400, 0, f + 20} > 0.5)
    assert.is_true(t:eval{400, 0, f + 20} < 0.5)
    local geo = oc.geology.strata{wavelength = 20, amplitude = 1}
    local er = oc.erosion(t, geo, {depth = 0.3})
    for _ = 1, 500 do
      local p = {rand(-700, 700), rand(-300, 300), rand(0, 350)}
      assert.is_true(er:eval(p) <= t:eval(p) + 1e-12)
    end
  end)

  it("polygonizes closed with its top on f", function()
    local m = oc.polygonize(t, {cell = 10})
    local st = m:stats()
    assert.is_true(st.triangles > 1000)
    -- closed and manifold: every edge in exactly two triangles, once
    -- each way
    local edges = {}
    for k = 1, st.triangles do
      local a, b, c = m:triangle(k)
      for _, e in ipairs({{a, b}, {b, c}, {c, a}}) do
        local key = e[1] * 4294967296 + e[2]
        assert.is_nil(edges[key], "edge used twice the same way")
        edges[key] = true
      end
    end
    for key in pairs(edges) do
      local a, b = key // 4294967296, key % 4294967296
      assert.is_true(edges[b * 4294967296 + a], "open edge")
    end
    local top, worst = 0, 0
    for i = 1, st.vertices, 7 do
      local x, y, z, _, _, nz = m:vertex(i)
      local f, a = scene:eval(x, y)
      if nz > 0.3 and a > 0.55 then
        worst = math.max(worst, math.abs(z - f))
        top = top + 1
      end
    end
    assert.is_true(top > st.vertices / 30)
    assert.is_true(worst < 10 / 200, "top vertex " .. worst .. " from f")
  end)
end)

describe("outcrop.heightfield.from of an elevation tree", function()
  it("gives f at every sample, exactly as a float", function()
    local hf = oc.heightfield.from(scene, {size = {61, 31}, cell = 20,
                                           origin = {-600, -300}})
    local nx, ny = hf:size()
    assert.are.same({61, 31}, {nx, ny})
    for j = 1, ny do
      for i = 1, nx do
        local f = scene:eval(-600 + (i - 1) * 20, -300 + (j - 1) * 20)
        assert.are.equal(f32(f), hf:get(i, j))
      end
    end
  end)

  it("covers the terrain box by default (513 samples along its longer side)", function()
    local hf = oc.heightfield.from(scene)
    local nx, ny = hf:size()
    local x0, y0, _, x1, y1 = oc.terrain(scene):bounds()
    assert.are.equal(513, math.max(nx, ny))
    local c = hf:cell()
    R.close(c, math.max(x1 - x0, y1 - y0) / 512, 1e-9, "cell")
    local a0, b0 = hf:bounds()
    assert.are.same({x0, y0}, {a0, b0})
    assert.is_true(y0 + (ny - 1) * c >= y1 - 1e-9 and y0 + (ny - 2) * c < y1)
    -- a cell alone: enough samples to cover the box
    local h2 = oc.heightfield.from(scene, {cell = 25})
    local mx = h2:size()
    assert.are.equal(math.ceil((x1 - x0) / 25) + 1, mx)
  end)

  it("puts 'holes' where alpha < 1/2, f elsewhere", function()
    local hf = oc.heightfield.from(scene, {size = {81, 21}, cell = 17,
                                           origin = {-680, -170}, holes = -999})
    local holes = 0
    for j = 1, 21 do
      for i = 1, 81 do
        local f, a = scene:eval(-680 + (i - 1) * 17, -170 + (j - 1) * 17)
        if a >= 0.5 then
          assert.are.equal(f32(f), hf:get(i, j))
        else
          assert.are.equal(-999, hf:get(i, j))
          holes = holes + 1
        end
      end
    end
    assert.is_true(holes > 100, holes .. " holes")
  end)

  it("is the same to the byte on one and two threads", function()
    local function child(threads)
      return R.child_output(threads,
        "local oc = require \"outcrop\" local E = oc.elevation " ..
        "local e = E.blend{E.disc{center = {0, 0}, radius = 900, height = 50, " ..
        "noise = {kind = \"turbulence\", amplitude = 80, wavelength = 150}}, " ..
        "E.disc{center = {200, 100}, radius = 400, height = 300}} " ..
        "local hf = oc.heightfield.from(e, {size = {300, 200}, cell = 2.7, " ..
        "origin = {-400, -270}}) local t = {} " ..
        "for j = 1, 200 do for i = 1, 300 do " ..
        "t[#t + 1] = string.pack(\"f\", hf:get(i, j)) end end " ..
        "io.write(table.concat(t))")
    end
    local one, two = child(1), child(2)
    assert.are.equal(300 * 200 * 4, #one)
    assert.is_true(one == two)
  end)

  it("refuses bad fields, naming them and the line", function()
    local fn = "outcrop.heightfield.from"
    check(function() oc.heightfield.from(scene, {size = {1, 5}}) end, fn, "'size'")
    check(function() oc.heightfield.from(scene, {cell = -1}) end, fn, "'cell'")
    check(function() oc.heightfield.from(scene, {cell = 0 / 0}) end, fn, "'cell'")
    check(function() oc.heightfield.from(scene, {cell = 1e-4}) end, fn, "'cell'")
    check(function() oc.heightfield.from(scene, {origin = {0}}) end, fn, "'origin'")
    check(function() oc.heightfield.from(scene, {origin = {1e6, 1e6}}) end, fn, "'origin'")
    check(function() oc.heightfield.from(scene, {holes = math.huge}) end, fn, "'holes'")
    check(function() oc.heightfield.from(scene, {holes = "x"}) end, fn, "'holes'")
    check(function() oc.heightfield.from(scene, {zrange = {0, 1}}) end, fn, "zrange")
  end)
end)

describe("outcrop.terrain of a tree: bad input", function()
  local fn = "outcrop.terrain"
  it("names the field and the line", function()
    check(function() oc.terrain(scene, {domain = {0, 0, 0, 10}}) end, fn, "'domain'")
    check(function() oc.terrain(scene, {domain = {0, 0, 1 / 0, 10}}) end, fn, "'domain'")
    check(function() oc.terrain(scene, {domain = {0, 0, 1}}) end, fn, "'domain'")
    check(function() oc.terrain(scene, {falloff = -2}) end, fn, "'falloff'")
    check(function() oc.terrain(scene, {falloff = 0 / 0}) end, fn, "'falloff'")
    check(function() oc.terrain(scene, {transition = 0}) end, fn, "'transition'")
    check(function() oc.terrain(scene, {thickness = -1}) end, fn, "'thickness'")
    check(function() oc.terrain(scene, {edges = "round"}) end, fn, "'edges'")
    check(function() oc.terrain(scene, {mask = "m.png"}) end, fn, "'mask'", "heightfield")
    check(function() oc.terrain(scene, {edges = "slab", falloff = 5000}) end, fn, "'falloff'")
    check(function() oc.terrain(scene, {bogus = 1}) end, fn, "bogus")
    check(function() oc.terrain(42) end, fn, "heightfield or an elevation tree")
  end)
end)

describe("the sea-erosion generator on an implicitized tree", function()
  -- a headland: land at 40 m rising from a sea floor at -12 m
  local floor = E.disc{center = {0, 0}, radius = 400, height = -12}
  local land = E.disc{center = {0, 0}, radius = 160, height = 40,
                      noise = {amplitude = 8, wavelength = 60, octaves = 3}}
  local coast = E.blend{floor, land}
  local t = oc.terrain(coast)
  local hf = oc.heightfield.from(coast, {cell = 3})

  it("carves the coast around sea level and nothing far from it", function()
    local n, info = oc.generate.sea{heightfield = hf, terrain = t, seed = 3,
                                    sea_level = 0, range = 4, radius = 3,
                                    spacing = 1.5, steps = 2, strength = 4}
    assert.is_true(info.primitives > 20, info.primitives .. " primitives")
    local carved = 0
    for _ = 1, 8000 do
      local p = {rand(-180, 180), rand(-180, 180), rand(-14, 42)}
      local fe, ft = n:eval(p), t:eval(p)
      assert.is_true(fe <= ft + 1e-12)
      if math.abs(p[3]) > 4 + 3 + 1e-9 then
        assert.is_true(math.abs(fe - ft) <= 1e-12)
      elseif ft > 0.5 and fe <= 0.5 then
        carved = carved + 1
      end
    end
    assert.is_true(carved > 5, carved .. " carved")
  end)
end)

describe("hoodoos and karst on an implicitized tree", function()
  -- a plateau 40 m up (the blend of 20 and 60), its edge where the
  -- weights fall below 1/2
  local plateau = E.blend{E.disc{center = {0, 0}, radius = 300, height = 20},
                          E.disc{center = {0, 0}, radius = 200, height = 60,
                                 noise = {amplitude = 6, wavelength = 40}}}
  local t = oc.terrain(plateau)
  local hf = oc.heightfield.from(plateau, {cell = 2})

  it("grows hoodoos on it, adding to the ground only", function()
    local n, info = oc.generate.hoodoos{heightfield = hf, terrain = t, seed = 3}
    assert.is_true(info.hoodoos > 3, info.hoodoos .. " hoodoos")
    assert.are.equal(info.primitives + 1, n:stats().primitives)
    local grew = 0
    for _ = 1, 3000 do
      local p = {rand(-130, 130), rand(-130, 130), rand(10, 70)}
      local fn, ft = n:eval(p), t:eval(p)
      assert.is_true(fn >= ft - 1e-12)
      if fn > 0.5 and ft <= 0.5 then grew = grew + 1 end
    end
    assert.is_true(grew > 0)
  end)

  it("carves karst under its surface", function()
    local geo = oc.geology.layer{origin = {0, 0, 35}, normal = {0, 0, 1},
                                 radius = 8, resistance = -0.6,
                                 noise = {wavelength = 10, amplitude = 0.2,
                                          offset = 0.7, octaves = 3, seed = 11}}
    local k, info = oc.generate.karst{heightfield = hf, terrain = t,
                                      geology = geo, radius = 4,
                                      sinks = {{0, 0, 35}}, max_primitives = 60}
    assert.is_true(info.primitives > 10, info.primitives .. " cavities")
    assert.is_true(k:eval{0, 0, 35} < 0.5 and t:eval{0, 0, 35} > 0.5)
  end)
end)
