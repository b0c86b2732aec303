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

describe("erosion generators", function()
  it("take a huge spacing without writing out of bounds", function()
    for _, gen in ipairs{oc.generate.river, oc.generate.sea} do
      local n, st = gen{heightfield = valley, spacing = 1e308}
      assert.is_true(st.columns <= 1) -- one disk covers the footprint
      assert.is_not_nil(n)
    end
  end)

  it("refuse odd spacings naming the field, or run", function()
    for _, v in ipairs(odd) do
      for _, name in ipairs{"river", "sea"} do
        local ok, err = pcall(oc.generate[name], {heightfield = valley, spacing = v})
        if not ok then
          assert.matches("outcrop.generate." .. name .. ": .*'spacing'", err)
          assert.matches("^" .. F .. ":%d+:", err)
        end
      end
    end
  end)

  it("bound the bank rays by the grid: depth and radius cost no more", function()
    local t0 = os.clock()
    for _, t in ipairs{{depth = 1e7}, {depth = 1e308}, {radius = 1e5, depth = 0.01},
                       {radius = 1e308}} do
      t.heightfield, t.spacing = valley, 1
      local ok, err = pcall(oc.generate.river, t)
      if not ok then assert.matches("'radius'", err) end
    end
    assert.is_true(os.clock() - t0 < 20)
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
    for _, v in ipairs(odd) do
      local ok, err = pcall(oc.polygonize, plane, {box = {0, 0, -1, 4, 4, 1}, cell = v})
      if not ok then
        assert.matches("^" .. F .. ":%d+: outcrop.polygonize: .*'cell'", err)
      end
      ok, err = pcall(oc.polygonize, plane, {box = {0, 0, -1, v, 4, 1}})
      if not ok then
        assert.matches("^" .. F .. ":%d+: outcrop.polygonize: .*'box'", err)
      end
    end
  end)
end)
