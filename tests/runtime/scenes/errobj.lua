-- errobj.lua: errors that are not strings.
if arg[1] == "tostring" then
  error(setmetatable({}, {__tostring = function() return "custom error object" end}))
end
error({code = 7})
