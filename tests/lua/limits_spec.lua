-- limits_spec.lua — odd and huge numbers from scripts: sizes derived from
-- them are refused with the function, the field, the figure and the
-- script line before anything is allocated, and calls whose output or
-- work would grow without bound are refused up front or bounded by the
-- grid.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "limits_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local H = oc.heightfield

-- A valley along y sloping down to y = 0.
local valley = H.from(function(x, y) return 0.2 * y + 0.6 * math.abs(x - 20) end,
                      {size = {41, 41}, cell = 1})

local odd = {0 / 0, math.huge, -math.huge, -0.0, 1e308, 1e-308, 5e-324,
             math.maxinteger, math.mininteger, -1, 2 ^ 53}

-- Calls f with each odd number: `want` has one letter per number, in
-- odd's order: "E" an error naming the function (fname), the field and
-- the script line, "." a result. Returns the mismatches, one a line.
local function outcomes(want, f, fname, field)
  local bad = {}
  for i, v in ipairs(odd) do
    local ok, err = pcall(f, v)
    local expect_error = want:sub(i, i) == "E"
    if ok and expect_error then
      bad[#bad + 1] = string.format("%s with %s: no error", fname, tostring(v))
    elseif not ok and not expect_error then
      bad[#bad + 1] = string.format("%s with %s: %s", fname, tostring(v), tostring(err))
    elseif not ok and not (tostring(err):find(F .. ":%d+: " .. fname:gsub("%.", "%%.") .. ": ")
                           and tostring(err):find(field, 1, true)) then
      bad[#bad + 1] = string.format("%s with %s: %q lacks the line, %s or %s", fname,
                                    tostring(v), tostring(err), fname, field)
    end
  end
  return table.concat(bad, "\n")
end

describe("erosion generators", function()
  it("take a huge spacing without writing out of bounds", function()
    for _, gen in ipairs{oc.generate.river, oc.generate.sea} do
      local n, st = gen{heightfield = valley, spacing = 1e308}
      assert.is_true(st.columns <= 1) -- one disk covers the footprint
      assert.is_not_nil(n)
    end
  end)

  -- not positive: refused; 1e-308 and 5e-324: too many columns; 1e308,
  -- maxinteger and 2^53: one disk covers the footprint
  it("refuse odd spacings naming the field, or run on one column", function()
    for _, name in ipairs{"river", "sea"} do
      assert.are.equal("", outcomes("EEEE.EE.EE.", function(v)
        return oc.generate[name]{heightfield = valley, spacing = v}
      end, "outcrop.generate." .. name, "'spacing'"))
    end
  end)

  it("refuse more columns x steps than the primitive budget, with the figure", function()
    local t = {heightfield = valley, banks = 64, spacing = 0.04, steps = 64}
    check(function() oc.generate.river(t) end, "outcrop.generate.river", "'spacing'",
          "'steps'", "primitives (at most 20 million)")
  end)

  it("bound the bank rays by the grid: depth and radius cost no more", function()
    local t0 = os.clock()
    for _, t in ipairs{{depth = 1e7}, {depth = 1e308}, {radius = 1e5, depth = 0.01},
                       {radius = 1e308}} do
      t.heightfield, t.spacing = valley, 1
      assert.is_not_nil(oc.generate.river(t))
    end
    assert.is_true(os.clock() - t0 < 20)
  end)
end)

describe("heightfield sizes", function()
  it("refuse more than 2^28 samples, with the figure", function()
    local t = {size = {65535, 65535}, wavelength = 5, amplitude = 1}
    check(function() H.fbm(t) end, "outcrop.heightfield.fbm",
          "'size' 65535 x 65535 is 4294836225 samples (16383 MiB), over the limit of 268435456")
    local sph = oc.sphere{center = {0, 0, 0}, radius = 5}
    local u = {size = {20000, 20000}}
    check(function() H.from(sph, u) end, "outcrop.heightfield.from", "'size' 20000 x 20000")
    local v = {cell = 0.001}
    check(function() valley:resample(v) end, "heightfield:resample",
          "'cell' 0.001 gives 40001 x 40001 samples, over the limit of 268435456")
  end)

  it("refuse subnormal cells (half a cell would be 0: erosion rays never advanced)", function()
    local t = {size = {24, 24}, cell = 5e-324, wavelength = 8, amplitude = 0.25}
    check(function() H.fbm(t) end, "outcrop.heightfield.fbm",
          "'cell' must be a positive normal number")
    t.cell = 1e-300 -- tiny but normal: the sea generator ends
    local hf = H.fbm(t)
    local scene, info = oc.generate.sea{heightfield = hf, terrain = false, radius = 6}
    assert.is_not_nil(scene)
    assert.is_table(info)
  end)
end)

describe("Poisson sampling", function()
  it("refuses a radius too small for the box, with the bound", function()
    local t = {box = {0, 0, 1e6, 1e6}, radius = 0.01}
    check(function() oc.poisson2d(t) end, "outcrop.poisson2d", "'radius' 0.01 is too small",
          "samples could fit (at most 50 million")
  end)
end)

describe("outcrop.slice", function()
  it("refuses more pixels than the renderer's limit, with the figure", function()
    local sph = oc.sphere{center = {0, 0, 0}, radius = 5}
    local t = {size = {16384, 16384}}
    check(function() oc.slice(sph, t) end, "outcrop.slice",
          "'size' 16384 x 16384 is 268435456 pixels, over the limit of 33554432")
  end)
end)

describe("outcrop.polygonize", function()
  local plane = oc.plane{origin = {0, 0, 0}, normal = {0, 0, 1}}

  it("refuses a mesh projected beyond max_triangles, with the figure", function()
    local huge = {box = {-250000, -250000, -1, 250000, 250000, 1}, cell = 2}
    check(function() oc.polygonize(plane, huge) end, "outcrop.polygonize",
          "about 2.5e+11 triangles", "'max_triangles' (134217728)")
    local small = {box = {0, 0, -2, 100, 100, 2}, cell = 1, max_triangles = 30000}
    check(function() oc.polygonize(plane, small) end, "outcrop.polygonize",
          "about 4.08e+04 triangles", "'max_triangles' (30000)")
    local m = oc.polygonize(plane, {box = {0, 0, -2, 100, 100, 2}, cell = 1,
                                    max_triangles = 50000})
    local _, nt = m:counts()
    assert.is_true(nt >= 40804 and nt < 50000)
  end)

  it("checks max_triangles", function()
    for _, v in ipairs{0, -1, 0.5, 1e308, 0 / 0, math.huge, math.maxinteger, "x"} do
      local t = {box = {0, 0, -1, 4, 4, 1}, max_triangles = v}
      check(function() oc.polygonize(plane, t) end, "outcrop.polygonize", "'max_triangles'")
    end
  end)

  it("refuses odd cells and boxes naming the field", function()
    -- cell: not positive, or too small for the box; box: x1 not finite or
    -- not above x0 (a huge or tiny x1 is a box, meshed at the default cell)
    assert.are.equal("", outcomes("EEEE.EE.EE.", function(v)
      return oc.polygonize(plane, {box = {0, 0, -1, 4, 4, 1}, cell = v})
    end, "outcrop.polygonize", "'cell'"))
    assert.are.equal("", outcomes("EEEE....EE.", function(v)
      return oc.polygonize(plane, {box = {0, 0, -1, v, 4, 1}})
    end, "outcrop.polygonize", "'box'"))
  end)
end)

-- One valid call per numeric field of the API, with the field replaced by
-- each odd number: the call returns, or raises an error naming the
-- function, the field (or the field derived from it: spacing = radius / 2)
-- and this file's line; never a crash (ASan build). Which of the two is
-- fixed per number: the third item has a letter per number of `odd`, in
-- order, "E" for the error and "." for a result.
describe("odd numbers in every numeric field", function()
  local sph = oc.sphere{center = {0, 0, 0}, radius = 5}
  local hf = valley
  local cases = {
  {"outcrop.heightfield.fbm", "'size'", "EEEEEEEEEEE", function(v) return H.fbm{size = {v, 10}, wavelength = 5, amplitude = 1} end},
  {"outcrop.heightfield.fbm", "'cell'", "EEEE.EE.EE.", function(v) return H.fbm{size = {10, 10}, cell = v, wavelength = 5, amplitude = 1} end},
  {"outcrop.heightfield.fbm", "'wavelength'", "EEEE....EE.", function(v) return H.fbm{size = {10, 10}, wavelength = v, amplitude = 1} end},
  {"outcrop.heightfield.fbm", "'amplitude'", "EEE.E......", function(v) return H.fbm{size = {10, 10}, wavelength = 5, amplitude = v} end},
  {"outcrop.heightfield.fbm", "'octaves'", "EEEEEEEEEEE", function(v) return H.fbm{size = {10, 10}, wavelength = 5, amplitude = 1, octaves = v} end},
  {"outcrop.heightfield.fbm", "'origin'", "EEE........", function(v) return H.fbm{size = {10, 10}, wavelength = 5, amplitude = 1, origin = {v, 0}} end},
  {"outcrop.heightfield.from", "'cell'", "EEEE.EE.EE.", function(v) return H.from(function() return 0 end, {size = {10, 10}, cell = v}) end},
  {"outcrop.heightfield.from", "'cell'", "EEEE.EE.EE.", function(v) return H.from(sph, {size = {10, 10}, cell = v, origin = {-5, -5}}) end},
  {"outcrop.heightfield.from", "'zrange'", "EEE.E...EE.", function(v) return H.from(sph, {size = {10, 10}, zrange = {-1, v}}) end},
  {"outcrop.heightfield.from", "'zrange'", "EEE.E..E..E", function(v) return H.from(sph, {size = {10, 10}, zrange = {v, 1}}) end},
  {"outcrop.heightfield.from", "'origin'", "EEE........", function(v) return H.from(sph, {size = {10, 10}, origin = {v, 1}}) end},
  {"heightfield:resample", "'cell'", "EEEEEEEEEEE", function(v) return hf:resample{cell = v} end},
  {"heightfield:resample", "'size'", "EEEEEEEEEEE", function(v) return hf:resample{size = {v, v}} end},
  {"heightfield:crop", "item 3", "EEEEEEEEEEE", function(v) return hf:crop{1, 1, v, 5} end},
  {"heightfield:crop", "'box'", "EEEE.EE.EE.", function(v) return hf:crop{box = {0, 0, v, 5}} end},
  {"heightfield:crop", "'box'", "EEE.E..E..E", function(v) return hf:crop{box = {v, 0, 30, 5}} end},
  {"heightfield:accessibility", "'rays'", "EEEEEEEEEEE", function(v) return hf:accessibility{rays = v} end},
  {"heightfield:accessibility", "'distance'", "EEEE....EE.", function(v) return hf:accessibility{distance = v, rays = 4} end},
  {"heightfield:drainage", "exponent", "EEEEE..EEEE", function(v) return hf:drainage{exponent = v} end},
  {"heightfield:distance_to_level", "level", "E.E.....EE.", function(v) return hf:distance_to_level(v) end},
  {"heightfield:", " must be", "EEE........", function(v) return hf:height(v, 3), hf:gradient(3, v) end},
  {"heightfield:get", "i must", "EEEEEEEEEEE", function(v) return hf:get(v, 1) end},
  {"outcrop.terrain", "'falloff'", "EEEE....EE.", function(v) return oc.terrain(hf, {falloff = v}):eval{1,1,1} end},
  {"outcrop.terrain", "'thickness'", "EEE.....EE.", function(v) return oc.terrain(hf, {thickness = v}):eval{1,1,1} end},
  {"outcrop.terrain", "'transition'", "EEEE....EE.", function(v) return oc.terrain(hf, {transition = v}):eval{1,1,1} end},
  {"outcrop.poisson2d", "'radius'", "EEEE.EE.EE.", function(v) return oc.poisson2d{box = {0, 0, 10, 10}, radius = v} end},
  {"outcrop.poisson2d", "'box'", "EEEEEEEEEEE", function(v) return oc.poisson2d{box = {0, 0, v, 10}, radius = 1} end},
  {"outcrop.poisson2d", "'box'", "EEE.E..EE.E", function(v) return oc.poisson2d{box = {v, 0, 10, 10}, radius = 1} end},
  {"outcrop.poisson3d", "'radius'", "EEEE.EE.EE.", function(v) return oc.poisson3d{box = {0, 0, 0, 10, 10, 10}, radius = v} end},
  {"outcrop.poisson3d", "'box'", "EEEEEEEEEEE", function(v) return oc.poisson3d{box = {0, 0, 0, 10, 10, v}, radius = 1} end},
  {"outcrop.generate.sea", "'radius'|'spacing'", "EEEE.EE.EE.", function(v) return oc.generate.sea{heightfield = hf, radius = v} end},
  {"outcrop.generate.sea", "'range'|'spacing'", "EEEE.EE.EE.", function(v) return oc.generate.sea{heightfield = hf, range = v} end},
  {"outcrop.generate.sea", "'sea_level'", "EEE........", function(v) return oc.generate.sea{heightfield = hf, sea_level = v} end},
  {"outcrop.generate.sea", "'reach'", "EEEE....EE.", function(v) return oc.generate.sea{heightfield = hf, reach = v} end},
  {"outcrop.generate.sea", "'rays'", "EEE.EEEEEEE", function(v) return oc.generate.sea{heightfield = hf, rays = v} end},
  {"outcrop.generate.sea", "'steps'", "EEEEEEEEEEE", function(v) return oc.generate.sea{heightfield = hf, steps = v} end},
  {"outcrop.generate.sea", "'strength'", "EEEE....EE.", function(v) return oc.generate.sea{heightfield = hf, strength = v} end},
  {"outcrop.generate.river", "'power'", "EEEE....EE.", function(v) return oc.generate.river{heightfield = hf, power = v} end},
  {"outcrop.generate.river", "'banks'", "EEE.EEEEEEE", function(v) return oc.generate.river{heightfield = hf, banks = v} end},
  {"outcrop.generate.river", "'depth'", "EEEE....EE.", function(v) return oc.generate.river{heightfield = hf, depth = v} end},
  {"outcrop.generate.river", "'spacing'", "EEEE.EE.EE.", function(v) return oc.generate.river{heightfield = hf, spacing = v} end},
  {"outcrop.generate.karst", "'spacing'", "EEEE.EE.EE.", function(v) return oc.generate.karst{heightfield = hf, spacing = v} end},
  {"outcrop.generate.karst", "'radius'|'spacing'", "EEEEEEEEEEE", function(v) return oc.generate.karst{heightfield = hf, radius = v} end},
  {"outcrop.generate.karst", "'max_primitives'", "EEEEEEEEEEE", function(v) return oc.generate.karst{heightfield = hf, max_primitives = v} end},
  {"outcrop.generate.karst", "'step'", "EEEEE..EEEE", function(v) return oc.generate.karst{heightfield = hf, step = v} end},
  {"outcrop.generate.karst", "'cover'", "EEE.....EE.", function(v) return oc.generate.karst{heightfield = hf, cover = v} end},
  {"outcrop.generate.karst", "'floor'", "EEE.....E..", function(v) return oc.generate.karst{heightfield = hf, floor = v} end},
  {"outcrop.generate.karst", "'epsilon'", "EEE.....EE.", function(v) return oc.generate.karst{heightfield = hf, epsilon = v} end},
  {"outcrop.generate.karst", "'rho0'", "EEEEE..EEEE", function(v) return oc.generate.karst{heightfield = hf, rho0 = v} end},
  {"outcrop.generate.karst", "'energy'", "EEEE....EE.", function(v) return oc.generate.karst{heightfield = hf, energy = v} end},
  {"outcrop.generate.karst", "'beta'", "EEE.E..EEEE", function(v) return oc.generate.karst{heightfield = hf, beta = v} end},
  {"outcrop.generate.karst", "'branches'", "EEEEEEEEEEE", function(v) return oc.generate.karst{heightfield = hf, branches = v} end},
  {"outcrop.generate.hoodoos", "'width'", "EEEEEEEEEEE", function(v) return oc.generate.hoodoos{heightfield = hf, width = v} end},
  {"outcrop.generate.hoodoos", "'margin'", "EEE.E..EEEE", function(v) return oc.generate.hoodoos{heightfield = hf, margin = v} end},
  {"outcrop.generate.hoodoos", "'p_block'", "EEE.E..EEEE", function(v) return oc.generate.hoodoos{heightfield = hf, p_block = v} end},
  {"outcrop.generate.hoodoos", "'p_cone'", "EEE.E..EEEE", function(v) return oc.generate.hoodoos{heightfield = hf, p_cone = v} end},
  {"outcrop.generate.hoodoos", "'shrink'", "EEEEEEEEEEE", function(v) return oc.generate.hoodoos{heightfield = hf, shrink = v} end},
  {"outcrop.generate.hoodoos", "'tilt'", "EEE.E..EEEE", function(v) return oc.generate.hoodoos{heightfield = hf, tilt = v} end},
  {"outcrop.generate.hoodoos", "'roughness'", "EEE.E..EEEE", function(v) return oc.generate.hoodoos{heightfield = hf, roughness = v} end},
  {"outcrop.generate.hoodoos", "'probability'", "EEE.E..EEEE", function(v) return oc.generate.hoodoos{heightfield = hf, probability = v} end},
  {"outcrop.generate.hoodoos", "'slope'", "EEE.....EE.", function(v) return oc.generate.hoodoos{heightfield = hf, slope = v} end},
  {"outcrop.generate.hoodoos", "'slope_spread'", "EEEE....EE.", function(v) return oc.generate.hoodoos{heightfield = hf, slope_spread = v} end},
  {"outcrop.generate.hoodoos", "'drainage'", "EEEE....EE.", function(v) return oc.generate.hoodoos{heightfield = hf, drainage = v} end},
  {"outcrop.generate.hoodoos", "'height'", "EEEEEEEEEEE", function(v) return oc.generate.hoodoos{heightfield = hf, height = {1, v}} end},
  {"outcrop.generate.river", "'beta'", "EEE.E..EEEE", function(v) return oc.generate.river{heightfield = hf, beta = v} end},
  {"outcrop.generate.river", "'cutoff'", "EEE.....EE.", function(v) return oc.generate.river{heightfield = hf, cutoff = v} end},
  {"outcrop.generate.river", "'strength'", "EEEE....EE.", function(v) return oc.generate.river{heightfield = hf, strength = v} end},
  {"outcrop.generate.hoodoos", "'radius'|'spacing'", "EEEE.EE.EE.", function(v) return oc.generate.hoodoos{heightfield = hf, radius = v} end},
  {"outcrop.generate.hoodoos", "'spacing'", "EEEEEEEEEEE", function(v) return oc.generate.hoodoos{heightfield = hf, spacing = v} end},
  {"outcrop.generate.hoodoos", "'max_depth'", "EEEEEEEEEEE", function(v) return oc.generate.hoodoos{heightfield = hf, max_depth = v} end},
  {"outcrop.slice", "'at'", "EEE........", function(v) return oc.slice(sph, {at = v, size = {8, 8}}) end},
  {"outcrop.slice", "'size'", "EEEEEEEEEEE", function(v) return oc.slice(sph, {size = {v, 8}}) end},
  {"outcrop.slice", "'box'", "EEE.....EE.", function(v) return oc.slice(sph, {box = {-1, -1, v, 1}, size = {8, 8}}) end},
  {"outcrop.render", "'size'", "EEEEEEEEEEE", function(v) return oc.render(sph, {size = {v, 8}}) end},
  {"outcrop.render", "'camera.fov'", "EEEEE..EEEE", function(v) return oc.render(sph, {size = {8, 8}, camera = {eye = {0, -20, 0}, target = {0, 0, 0}, fov = v}}) end},
  {"outcrop.render", "'camera.eye'", "EEEEEEE....", function(v) return oc.render(sph, {size = {8, 8}, camera = {eye = {0, v, 0}, target = {0, 0, 0}}}) end},
  {"outcrop.polygonize", "'cell'", "EEEE.EE.EE.", function(v) return oc.polygonize(sph, {cell = v}) end},
  {"outcrop.polygonize", "resolution", "EEEEEEEEEEE", function(v) return oc.polygonize(sph, {resolution = {v, 4, 4}}) end},
  {"outcrop.polygonize", "'box'", "EEE.....EE.", function(v) return oc.polygonize(sph, {box = {-1, -1, -1, v, 1, 1}, resolution = {4, 4, 4}}) end},
  {"outcrop.polygonize", "'steps'", "EEEEEEEEEEE", function(v) return oc.polygonize(sph, {steps = v}) end},
  }
  it("give a result or an error naming the function and the field", function()
    local bad = {}
    for _, c in ipairs(cases) do
      local fname, field, want, call = c[1], c[2], c[3], c[4]
      for i, v in ipairs(odd) do
        local ok, err = pcall(call, v)
        if ok ~= (want:sub(i, i) == ".") then
          bad[#bad + 1] = string.format("%s with %s: %s", fname, tostring(v),
                                        ok and "a result, not the error" or err)
        elseif not ok then
          local where = F .. ":" .. debug.getinfo(call, "S").linedefined .. ": "
          local named = false
          for alt in field:gmatch("[^|]+") do named = named or err:find(alt, 1, true) end
          if not (err:find(where .. fname, 1, true) and named) then
            bad[#bad + 1] = string.format("%s with %s: %q lacks %q or %q", fname,
                                          tostring(v), err, where .. fname, field)
          end
        end
      end
    end
    assert.are.same({}, bad)
  end)
end)
