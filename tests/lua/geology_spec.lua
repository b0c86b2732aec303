-- geology_spec.lua — outcrop.geology (resistance trees) and outcrop.erosion:
-- every constructor against its formula (docs/fields.md, "Geology"), the
-- fault's discontinuity, erosion never adding material, Lipschitz bounds
-- and gradients, slices and mesh colours by resistance, and every error
-- with its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "geology_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local G = oc.geology

-- the vertical line strata sample the turbulence on (docs/fields.md)
local SX, SY = 0.318309886, 0.587785252

local rng_state = 12345
local function rand(lo, hi)
  rng_state = (rng_state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * rng_state / 2147483648
end
local function rpoint(s)
  s = s or 40
  return {rand(-s, s), rand(-s, s), rand(-s, s)}
end
local function clamp(v, lo, hi) return math.max(lo, math.min(hi, v)) end

-- Largest |f(p) - f(q)| / |p - q| over random pairs, close and far.
local function max_slope(node, n, s)
  local m = 0
  for i = 1, n do
    local p = rpoint(s)
    local q = i % 2 == 0 and rpoint(s)
      or R.add(p, {rand(-1e-3, 1e-3), rand(-1e-3, 1e-3), rand(-1e-3, 1e-3)})
    local d = R.len(R.sub(p, q))
    if d > 0 then m = math.max(m, math.abs(node:eval(p) - node:eval(q)) / d) end
  end
  return m
end

describe("outcrop.geology.strata", function()
  local nz = {wavelength = 7, amplitude = 0.8, offset = 0.1, octaves = 5, seed = 4}
  local s = G.strata(nz)
  -- the same noise as a turbulence sampled on the line (SX, SY)
  local t = oc.turbulence{wavelength = 7, amplitude = 0.8 / R.tmax(5),
                          offset = 0.1, octaves = 5, seed = 4}

  it("is t(p_z / wavelength), normalised, independent of x and y", function()
    local lo, hi = math.huge, -math.huge
    for _ = 1, 500 do
      local p = rpoint()
      local v = s:eval(p)
      R.close(v, t:eval(SX * 7, SY * 7, p[3]), 1e-9, "strata")
      assert.are.equal(v, s:eval(rand(-1e4, 1e4), rand(-1e4, 1e4), p[3]))
      assert.is_true(v >= 0.1 and v <= 0.9)
      lo, hi = math.min(lo, v), math.max(hi, v)
    end
    assert.is_true(hi - lo > 0.3)
    assert.are.equal("strata", s:kind())
  end)

  it("has a valid Lipschitz bound and a vertical analytic gradient", function()
    assert.is_true(max_slope(s, 2000) <= s:lipschitz())
    for _ = 1, 50 do
      local p = rpoint()
      local gx, gy, gz = s:gradient(p)
      local ng = R.numgrad(s, p, 1e-5)
      assert.are.equal(0, gx)
      assert.are.equal(0, gy)
      R.close(gz, ng[3], 1e-6 + 1e-5 * math.abs(ng[3]), "d/dz")
    end
  end)

  it("is deterministic by seed", function()
    local a, b = G.strata{wavelength = 5, seed = 9}, G.strata{wavelength = 5, seed = 9}
    local c = G.strata{wavelength = 5, seed = 10}
    local differ = 0
    for i = 1, 50 do
      assert.are.equal(a:eval(0, 0, i * 0.7), b:eval(0, 0, i * 0.7))
      if math.abs(a:eval(0, 0, i * 0.7) - c:eval(0, 0, i * 0.7)) > 1e-3 then differ = differ + 1 end
    end
    assert.is_true(differ > 40)
  end)
end)

describe("outcrop.geology.layer, sphere, curve and blends", function()
  it("layer is resistance g(|d| / radius) + turbulence", function()
    local o, n = {0, 0, 5}, {0.2, 0.1, 1}
    local nu = R.mul(n, 1 / R.len(n))
    local noise = {wavelength = 4, amplitude = 0.1, octaves = 3, seed = 2}
    local l = G.layer{origin = o, normal = n, radius = 3, resistance = -0.6, noise = noise}
    local t = oc.turbulence(noise)
    for _ = 1, 400 do
      local p = R.add(rpoint(), {0, 0, 0})
      if rand(0, 1) < 0.5 then p[3] = 5 + rand(-4, 4) end
      local d = R.dot(R.sub(p, o), nu)
      R.close(l:eval(p), -0.6 * R.g(math.abs(d) / 3) + t:eval(p), 1e-12, "layer")
    end
    assert.is_true(max_slope(l, 2000) <= l:lipschitz())
  end)

  it("sphere and curve pockets are the primitives with energy = resistance", function()
    local sp = G.sphere{center = {1, 2, 3}, radius = 4, falloff = 2, resistance = 0.4}
    local ref = oc.sphere{center = {1, 2, 3}, radius = 4, falloff = 2, energy = 0.4}
    local pts = {{0, 0, 0}, {5, 0, 2}, {9, 3, 2}}
    local cv = G.curve{points = pts, radius = 2, resistance = -0.3}
    local cref = oc.curve{points = pts, radius = 2, energy = -0.3}
    for _ = 1, 300 do
      local p = rpoint(10)
      assert.are.equal(ref:eval(p), sp:eval(p))
      assert.are.equal(cref:eval(p), cv:eval(p))
    end
  end)

  it("blends by sum, and clamp keeps values in [0, 1]", function()
    local a = G.strata{wavelength = 5, seed = 1}
    local b = G.layer{origin = {0, 0, 0}, normal = {0, 0, 1}, radius = 6, resistance = 0.9}
    local sum, c = a + b, G.clamp(a + b)
    local over = 0
    for _ = 1, 500 do
      local p = rpoint(10)
      R.close(sum:eval(p), a:eval(p) + b:eval(p), 1e-12, "sum")
      local v = c:eval(p)
      assert.is_true(v >= 0 and v <= 1)
      assert.are.equal(clamp(sum:eval(p), 0, 1), v)
      if sum:eval(p) > 1 then over = over + 1 end
    end
    assert.is_true(over > 20)
    local c2 = G.clamp(a, {lo = 0.2, hi = 0.6})
    for _ = 1, 100 do
      local p = rpoint()
      assert.are.equal(clamp(a:eval(p), 0.2, 0.6), c2:eval(p))
    end
  end)
end)

describe("fold, taper and fault", function()
  local s = G.strata{wavelength = 4, seed = 3}

  it("fold is the warp of the tree", function()
    local opts = {wavelength = 20, amplitude = 6, octaves = 2, seed = 5}
    local f, w = G.fold(s, opts), oc.warp(s, opts)
    local moved = 0
    for _ = 1, 300 do
      local p = rpoint()
      assert.are.equal(w:eval(p), f:eval(p))
      if math.abs(f:eval(p) - s:eval(p)) > 1e-3 then moved = moved + 1 end
    end
    assert.is_true(moved > 100)
    assert.is_true(max_slope(f, 1000) <= f:lipschitz())
  end)

  it("taper compresses strata by its factor past 'to'", function()
    local tp = G.taper(s, {to = 20, from = 0, factor = 2, height = 10})
    for _ = 1, 300 do
      local p = rpoint()
      local x = clamp(p[1] / 20, 0, 1)
      local k = 1 + (2 - 1) * x * x * (3 - 2 * x)
      local z = p[3] + (k - 1) * clamp(p[3], -10, 10)
      R.close(tp:eval(p), s:eval(p[1], p[2], z), 1e-12, "taper")
    end
    assert.is_true(max_slope(tp, 2000) <= tp:lipschitz())
  end)

  it("fault moves the tree strictly inside its domain", function()
    local off = {0, 0, 2.5}
    local box = G.fault(s, {domain = {min = {-10, -10, -10}, max = {10, 10, 10}}, offset = off})
    local half = G.fault(s, {domain = {origin = {3, 0, 0}, normal = {1, 0, 0}}, offset = off})
    local ball = oc.sphere{center = {0, 0, 0}, radius = 15}
    local nd = G.fault(s, {domain = ball, offset = off})
    for _ = 1, 500 do
      local p = rpoint(20)
      local moved = {p[1], p[2], p[3] - 2.5}
      local inbox = math.abs(p[1]) < 10 and math.abs(p[2]) < 10 and math.abs(p[3]) < 10
      assert.are.equal(s:eval(inbox and moved or p), box:eval(p))
      assert.are.equal(s:eval(p[1] < 3 and moved or p), half:eval(p))
      assert.are.equal(s:eval(ball:eval(p) > oc.threshold and moved or p), nd:eval(p))
    end
    -- on the face (open domain) the value is the outside one; just inside,
    -- the moved one
    local jumps = 0
    for _ = 1, 100 do
      local y, z = rand(-9, 9), rand(-9, 9)
      assert.are.equal(s:eval(10, y, z), box:eval(10, y, z))
      local x = 10 - 1e-9
      assert.are.equal(s:eval(x, y, z - 2.5), box:eval(x, y, z))
      if math.abs(box:eval(x, y, z) - box:eval(10, y, z)) > 1e-3 then jumps = jumps + 1 end
    end
    assert.is_true(jumps > 80)
    assert.are.equal(math.huge, box:lipschitz())
  end)
end)

describe("outcrop.erosion", function()
  local rock = oc.box{min = {-30, -30, -30}, max = {10, 30, 20}, falloff = 4}
  local geo = G.strata{wavelength = 6, amplitude = 1.2, offset = -0.1, seed = 21}
  local ctl = oc.box{min = {5, -40, -40}, max = {40, 40, 40}, falloff = 10}
  local e = oc.erosion(rock, geo, {control = ctl, depth = 0.7})

  it("is max(f - depth clamp(c) (1 - clamp(rho)), min(f, 0))", function()
    local eroded = 0
    for _ = 1, 3000 do
      local p = rpoint()
      local f = rock:eval(p)
      local want = math.max(f - 0.7 * clamp(ctl:eval(p), 0, 1) * (1 - clamp(geo:eval(p), 0, 1)), math.min(f, 0))
      R.close(e:eval(p), want, 1e-13, "erosion")
      assert.is_true(e:eval(p) <= f)
      if f - e:eval(p) > 0.05 then eroded = eroded + 1 end
    end
    assert.is_true(eroded > 100)
    assert.are.equal("erosion", e:kind())
  end)

  it("keeps the terrain's support and has a valid Lipschitz bound", function()
    local a = {e:bounds()}
    local b = {rock:bounds()}
    for i = 1, 6 do assert.are.equal(b[i], a[i]) end
    R.close(e:lipschitz(), rock:lipschitz() + 0.7 * (ctl:lipschitz() + geo:lipschitz()), 1e-12, "L")
    assert.is_true(max_slope(e, 3000) <= e:lipschitz())
    for _ = 1, 100 do
      local p = rpoint()
      if e:eval(p) > 0.05 then
        local gx, gy, gz = e:gradient(p)
        local ng = R.numgrad(e, p, 1e-6)
        R.close(gx, ng[1], 1e-5, "gx")
        R.close(gy, ng[2], 1e-5, "gy")
        R.close(gz, ng[3], 1e-5, "gz")
      end
    end
  end)

  it("meshes into a cliff with eroded strata, coloured by resistance", function()
    local m = oc.polygonize(e, {box = {-34, -10, -34, 14, 10, 24}, cell = 1,
      colors = {field = geo, palette = {{0, {0.2, 0.1, 0.1}}, {1, {1, 1, 0.9}}}}})
    local nv, nt = m:counts()
    assert.is_true(nt > 1000)
    -- the eroded face is recessed where the rock is soft: vertices of the
    -- +x face inside the control reach x < 10
    local recessed = 0
    for i = 1, nv do
      local x, y, z = m:vertex(i)
      if x < 8 and x > 0 and z < 15 and z > -25 and math.abs(y) < 9 then recessed = recessed + 1 end
    end
    assert.is_true(recessed > 50)
  end)

  it("works without a control (erodes wherever there is rock)", function()
    local all = oc.erosion(rock, geo, {depth = 0.3})
    for _ = 1, 300 do
      local p = rpoint()
      local f = rock:eval(p)
      R.close(all:eval(p), math.max(f - 0.3 * (1 - clamp(geo:eval(p), 0, 1)), math.min(f, 0)), 1e-13)
    end
  end)
end)

describe("slices by resistance", function()
  it("maps the resistance through the palette", function()
    local s = G.strata{wavelength = 5, seed = 2}
    local pal = {{0, {0, 0, 0}}, {1, {1, 0.5, 0.25}}}
    local img = G.slice(s, {plane = "xz", at = 0, box = {-10, -10, 10, 10}, size = {32, 32}, palette = pal})
    assert.are.equal(5, img:channels())
    for _ = 1, 50 do
      local i, j = math.floor(rand(1, 33)), math.floor(rand(1, 33))
      local r, g, b, a, f = img:get(i, j)
      local z = 10 - (j - 0.5) * 20 / 32
      R.close(f, s:eval(-10 + (i - 0.5) * 20 / 32, 0, z), 1e-6, "field")
      local v = clamp(f, 0, 1)
      R.close(r, v, 1e-6, "r")
      R.close(g, 0.5 * v, 1e-6, "g")
      R.close(b, 0.25 * v, 1e-6, "b")
      assert.are.equal(1, a)
    end
  end)
end)

describe("errors", function()
  local s = G.strata{wavelength = 5}
  local rock = oc.box{min = {0, 0, 0}, max = {1, 1, 1}}
  it("name the function, the field and the line", function()
    check(function() G.strata{wavelenght = 5} end, "outcrop.geology.strata", "unknown field 'wavelenght'")
    check(function() G.strata{wavelength = -1} end, "outcrop.geology.strata", "'wavelength'")
    check(function() G.strata{wavelength = 0 / 0} end, "outcrop.geology.strata", "'wavelength'")
    check(function() G.layer{origin = {0, 0, 0}, normal = {0, 0, 0}, radius = 1, resistance = 1} end, "outcrop.geology.layer", "'normal'")
    check(function() G.layer{origin = {0, 0, 0}, normal = {0, 0, 1}, radius = 1} end, "outcrop.geology.layer", "'resistance'")
    check(function() G.layer{origin = {0, 0, 0}, normal = {0, 0, 1}, radius = 1, resistance = 1, noise = 3} end, "outcrop.geology.layer", "'noise'")
    check(function() G.layer{origin = {0, 0, 0}, normal = {0, 0, 1}, radius = 1, resistance = 1, noise = {amplitude = 1}} end, "outcrop.geology.layer", "'noise.wavelength'")
    check(function() G.sphere{center = {0, 0, 0}, radius = 1} end, "outcrop.geology.sphere", "'resistance'")
    check(function() G.curve{points = {{0, 0, 0}}, radius = 1, resistance = 1} end, "outcrop.geology.curve", "'points'")
    check(function() G.fold(5, {wavelength = 1, amplitude = 1}) end, "outcrop.geology.fold", "argument #1 must be an outcrop node")
    check(function() G.fold(s, {wavelength = 1}) end, "outcrop.geology.fold", "'amplitude'")
    check(function() G.taper(s, {factor = 2, height = 1}) end, "outcrop.geology.taper", "'to'")
    check(function() G.taper(s, {to = 0, factor = 2, height = 1}) end, "outcrop.geology.taper", "'to' must differ from 'from'")
    check(function() G.taper(s, {to = 5, factor = 0, height = 1}) end, "outcrop.geology.taper", "'factor'")
    check(function() G.fault(s, {offset = {0, 0, 1}}) end, "outcrop.geology.fault", "'domain'")
    check(function() G.fault(s, {domain = 5, offset = {0, 0, 1}}) end, "outcrop.geology.fault", "'domain'")
    check(function() G.fault(s, {domain = {min = {0, 0, 0}, max = {1, 0, 1}}, offset = {0, 0, 1}}) end, "outcrop.geology.fault", "'domain.max'")
    check(function() G.fault(s, {domain = {origin = {0, 0, 0}, normal = {0, 0, 0}}, offset = {0, 0, 1}}) end, "outcrop.geology.fault", "'domain.normal'")
    check(function() G.fault(s, {domain = {min = {0, 0, 0}, max = {1, 1, 1}}}) end, "outcrop.geology.fault", "'offset'")
    check(function() G.clamp(s, {lo = 1, hi = 0}) end, "outcrop.geology.clamp", "'lo'")
    check(function() oc.erosion(rock, s, {}) end, "outcrop.erosion", "'depth'")
    check(function() oc.erosion(rock, s, {depth = -1}) end, "outcrop.erosion", "'depth'")
    check(function() oc.erosion(rock, s, {depth = 1, control = 3}) end, "outcrop.erosion", "'control'")
    check(function() oc.erosion(rock, 3, {depth = 1}) end, "outcrop.erosion", "argument #2")
    check(function() oc.erosion(rock, s) end, "outcrop.erosion", "argument #3")
    check(function() G.slice(s, {size = {8, 8}}) end, "outcrop.geology.slice", "'box'")
    check(function() G.slice(s, {box = {0, 0, 1, 1}, palette = {{0, {2, 0, 0}}}}) end, "outcrop.geology.slice", "'palette[1]'")
    check(function() G.slice(s, {box = {0, 0, 1, 1}, size = {0, 8}}) end, "outcrop.geology.slice", "'size'")
  end)
end)
