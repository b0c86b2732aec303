-- elevation_lod_spec.lua — level of detail of elevation trees
-- (Génevaux et al. 2015, section 6): outcrop.elevation.lod against its
-- formula with a footprint computed here, the views of e:eval and
-- e:gradient (k = 0 is full detail, far octaves vanish, gradients against
-- central differences), outcrop.render{lod = ...}, and every error with
-- its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "elevation_lod_spec.lua"
local E = oc.elevation

-- b(t) = 1 - (1 - t^2)^3 on [0, 1]
local function filt(t)
  if t <= 0 then return 0 end
  if t >= 1 then return 1 end
  local q = 1 - t * t
  return 1 - q * q * q
end

-- the footprint of a view at (x, y): dz from the tree's mid elevation
local function foot(e, view, x, y)
  local _, _, lo, _, _, hi = e:bounds()
  local dz = math.abs(view.eye[3] - (lo + hi) / 2)
  return view.k * math.sqrt((x - view.eye[1]) ^ 2 + (y - view.eye[2]) ^ 2 + dz ^ 2)
end

local function flat(h)
  return E.disc{center = {0, 0}, radius = 20000, height = h}
end

describe("outcrop.elevation.lod", function()
  it("blends a into b by the footprint: t = clamp((kappa - k0) / (k1 - k0))", function()
    local a, b = flat(10), flat(60)
    local l = E.lod(a, b, {wavelength = 300, k0 = 0.2, k1 = 0.7})
    assert.are.equal("lod", l:kind())
    local view = {eye = {0, 0, 500}, k = 0.1}
    local seen = {0, 0, 0}
    for x = 0, 4000, 7 do
      local kap = filt(math.log(300 / foot(l, view, x, 0), 2))
      local t = math.min(1, math.max(0, (kap - 0.2) / 0.5))
      local f, alpha = l:eval(x, 0, view)
      assert.is_true(math.abs(f - (10 + 50 * t)) < 1e-9, "x " .. x)
      -- both weights are the same disc's
      local w = (1 - (x / 20000) ^ 2) ^ 3
      assert.is_true(math.abs(alpha - w) < 1e-12)
      seen[t == 0 and 1 or t == 1 and 3 or 2] = seen[t == 0 and 1 or t == 1 and 3 or 2] + 1
    end
    for i = 1, 3 do assert.is_true(seen[i] > 10, "part " .. i) end
    -- without a view: b, full detail
    assert.are.equal(60, (l:eval(3000, 0)))
    assert.are.equal(60, (l:eval(3000, 0, {eye = {0, 0, 500}, k = 0})))
  end)

  it("has gradients that match central differences under a view", function()
    local base = E.disc{center = {0, 0}, radius = 20000, height = 50,
                        noise = {amplitude = 80, wavelength = 600, octaves = 8, seed = 2}}
    local l = E.lod(flat(10), base, {wavelength = 600})
    local view = {eye = {-1000, 200, 800}, k = 0.05}
    local n = 0
    for x = -6000, 6000, 173 do
      local y = 0.37 * x + 50
      local gx, gy = l:gradient(x, y, view)
      local h = 1e-4
      local fx = ((l:eval(x + h, y, view)) - (l:eval(x - h, y, view))) / (2 * h)
      local fy = ((l:eval(x, y + h, view)) - (l:eval(x, y - h, view))) / (2 * h)
      local sc = 1 + math.abs(fx) + math.abs(fy)
      assert.is_true(math.abs(gx - fx) < 1e-5 * sc and math.abs(gy - fy) < 1e-5 * sc,
                     string.format("(%g, %g): %g %g vs %g %g", x, y, gx, gy, fx, fy))
      n = n + 1
    end
    assert.is_true(n > 60)
  end)

  it("filters disc octaves: k = 0 is full detail, far away the noise is gone", function()
    local d = E.disc{center = {0, 0}, radius = 100000, height = 70,
                     noise = {kind = "ridged", amplitude = 100, wavelength = 500, octaves = 10}}
    local view = {eye = {0, 0, 300}, k = 1e-2}
    for _, p in ipairs{{100, 20}, {-2500, 700}, {9000, -3000}} do
      local f0, a0 = d:eval(p[1], p[2])
      local f1, a1 = d:eval(p[1], p[2], {eye = view.eye, k = 0})
      assert.are.equal(f0, f1)
      assert.are.equal(a0, a1)
    end
    -- the first octave (wavelength 500) is dropped where foot >= 500
    for x = 52001, 60000, 997 do
      local f = d:eval(x * 0.7, x * 0.7, view)
      assert.is_true(foot(d, view, x * 0.7, x * 0.7) >= 500)
      assert.are.equal(70, f)
    end
    -- at 3000 m the footprint is about 30 m: octaves 0 to 3 (wavelengths
    -- down to 62.5 m) are kept, and the dropped ones, in [0, 100 / 2^i]
    -- each, weigh at most 100 (1/16 + ... + 1/512) < 12.5
    local f0 = d:eval(3000, 0)
    local f1 = d:eval(3000, 0, view)
    assert.is_true(f0 ~= f1 and math.abs(f0 - f1) < 12.5)
  end)

  it("refuses bad input, naming the field", function()
    local a, b = flat(0), flat(1)
    R.check_error(function() E.lod(a, b, {}) end, F, "outcrop.elevation.lod", "'wavelength'")
    R.check_error(function() E.lod(a, b, {wavelength = 0 / 0}) end, F, "outcrop.elevation.lod", "'wavelength'")
    R.check_error(function() E.lod(a, b, {wavelength = 10, k0 = 0.5, k1 = 0.5}) end, F,
                  "outcrop.elevation.lod", "'k0' and 'k1' must satisfy 0 <= k0 < k1 <= 1")
    R.check_error(function() E.lod(a, b, {wavelength = 10, k1 = 2}) end, F,
                  "outcrop.elevation.lod", "'k1'")
    R.check_error(function() E.lod(a, b, {wavelength = 10, kk = 1}) end, F,
                  "outcrop.elevation.lod", "unknown field 'kk'")
    R.check_error(function() E.lod(a, 5, {wavelength = 10}) end, F,
                  "outcrop.elevation.lod", "argument #2 must be an elevation node")
    R.check_error(function() a:eval(0, 0, 5) end, F, "elevation:eval", "argument #3 must be a view")
    R.check_error(function() a:eval(0, 0, {k = 1}) end, F, "elevation:eval", "'eye'")
    R.check_error(function() a:eval(0, 0, {eye = {0, 0, 0}, k = -1}) end, F, "elevation:eval", "'k' must be >= 0")
    R.check_error(function() a:gradient(0, 0, {eye = {0, 0 / 0, 0}, k = 1}) end, F, "elevation:gradient", "'eye'")
    R.check_error(function() a:eval(0, 0, {eye = {0, 0, 0}, k = math.huge}) end, F, "elevation:eval", "'k'")
  end)
end)

describe("outcrop.render with lod", function()
  local function scene()
    local base = E.disc{center = {0, 0}, radius = 6000, height = 100,
                        noise = {amplitude = 120, wavelength = 1500, octaves = 10, seed = 5}}
    local hill = E.disc{center = {600, 300}, radius = 900, height = 300,
                        noise = {kind = "ridged", amplitude = 200, wavelength = 500, octaves = 10, seed = 6}}
    return E.blend{base, hill}
  end
  local cam = {eye = {-2500, -2200, 900}, target = {400, 300, 150}}
  -- channels: RGBA, then Z, N.x, N.y, N.z, P.x, P.y, P.z, evals
  local function chan(img, i, j, c) return (select(c, img:get(i, j))) end

  it("draws the same terrain as the exact render, up to the dropped details", function()
    local e = scene()
    local exact, se = oc.render(e, {size = {64, 36}, camera = cam, aov = true})
    local lod, sl = oc.render(e, {size = {64, 36}, camera = cam, aov = true, lod = true})
    assert.is_true(se.hits > 64 * 36 / 3)
    assert.is_true(math.abs(sl.hits - se.hits) <= 64 * 36 / 50)
    -- depths agree within a few percent where both hit (details below
    -- a pixel or two are gone)
    local off, both = 0, 0
    for j = 1, 36 do
      for i = 1, 64 do
        local ze = chan(exact, i, j, 5)
        local zl = chan(lod, i, j, 5)
        if ze and zl and ze == ze and zl == zl and ze < math.huge and zl < math.huge then
          both = both + 1
          if math.abs(ze - zl) > 0.05 * ze then off = off + 1 end
        end
      end
    end
    assert.is_true(both > 64 * 36 / 3)
    assert.is_true(off <= both / 20, off .. " of " .. both)
    -- the same on a second run, and c = 1 is the default
    local again = oc.render(e, {size = {64, 36}, camera = cam, aov = true, lod = {c = 1}})
    for j = 1, 36, 5 do
      for i = 1, 64, 3 do
        assert.are.same({lod:get(i, j)}, {again:get(i, j)})
      end
    end
    -- a coarser c keeps fewer details: fewer height calls to shade the
    -- same pixels is not promised, but the picture changes
    local coarse = oc.render(e, {size = {64, 36}, camera = cam, aov = true, lod = {c = 50}})
    local differ = 0
    for j = 1, 36 do
      for i = 1, 64 do
        if chan(coarse, i, j, 8) ~= chan(lod, i, j, 8) then differ = differ + 1 end
      end
    end
    assert.is_true(differ > 64 * 36 / 10)
  end)

  it("refuses bad lod fields", function()
    local e = scene()
    R.check_error(function() oc.render(e, {size = {4, 4}, lod = 5}) end, F, "outcrop.render",
                  "'lod' must be true, false or {c =}")
    R.check_error(function() oc.render(e, {size = {4, 4}, lod = {c = -1}}) end, F, "outcrop.render", "'lod.c'")
    R.check_error(function() oc.render(e, {size = {4, 4}, lod = {q = 1}}) end, F, "outcrop.render", "unknown field 'lod.q'")
    local hf = oc.heightfield.from(function(x, y) return x + y end, {size = {8, 8}, cell = 100})
    R.check_error(function() oc.render(hf, {size = {4, 4}, lod = true}) end, F, "outcrop.render",
                  "'lod' applies to elevation trees only")
  end)
end)
